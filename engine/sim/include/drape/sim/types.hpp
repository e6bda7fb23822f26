// Basic types of the cloth engine.
//
// The engine works in SI units: metres, seconds, kilograms. Single precision is enough for cloth
// (positions of a few metres resolved to micrometres) and halves memory traffic in the solver;
// accumulated quantities that need more (time, energy) are double.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

namespace drape::sim {

using Vec3 = glm::vec3;
// A particle is an index into its cloth's arrays, never a pointer.
using ParticleIndex = std::uint32_t;

}  // namespace drape::sim
