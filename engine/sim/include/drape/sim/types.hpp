// Basic types of the cloth engine.
//
// The engine works in SI units: metres, seconds, kilograms, in double precision. Single precision
// was tried first and measured: Verlet's x' = 2x - x_prev + a h^2 feeds each rounding of x back
// into the next velocity, so rounding grows with the square of the step count (a free fall from
// 2 m was 1e-4 m off after 72 substeps). That would put a floor under the accuracy study; doubles
// move the floor far below any discretisation error. `Real` is the one place to change it.
#pragma once

#include <cstdint>
#include <glm/ext/vector_int3_sized.hpp>
#include <glm/ext/vector_uint3_sized.hpp>
#include <glm/vec3.hpp>

namespace drape::sim {

using Real = double;
using Vec3 = glm::vec<3, Real>;
// A particle is an index into its cloth's arrays, never a pointer.
using ParticleIndex = std::uint32_t;

}  // namespace drape::sim
