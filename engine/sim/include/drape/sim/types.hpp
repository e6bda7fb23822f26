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
// Rest lengths (of constraints, lines and tethers) are in single precision. They are never
// integrated, so their rounding does not grow: it moves a rest length by 6e-8 of itself at most,
// far below any strain the solver leaves, and saves 4 bytes on each of the several rest lengths a
// particle has.
using RestReal = float;
// Particle masses too: they are parameters, never integrated, rounded once by 6e-8 of themselves
// (a tear shares a particle's mass out exactly, topology.cpp). Inverse masses stay in double.
using MassReal = float;
// A particle is an index into its cloth's arrays, never a pointer.
using ParticleIndex = std::uint32_t;

}  // namespace drape::sim
