// A cloth's runtime state, in structure-of-arrays form so each solver loop streams the arrays it
// needs and nothing else. (The solver's own working arrays are internal: src/solver_scratch.hpp.)
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "drape/sim/cloth.hpp"
#include "drape/sim/types.hpp"

namespace drape::sim {

struct ParticleState {
  std::vector<Vec3> position;          // m
  std::vector<Vec3> previousPosition;  // m, position one substep ago (Verlet's velocity-less memory)
  std::vector<Vec3> velocity;          // m/s, force model only; empty in the position model
  std::vector<Real> inverseMass;       // 1/kg; 0 for a pinned or held particle, which no force or constraint moves
  std::vector<MassReal> mass;          // kg, of every particle, pinned or not (toMass)
  std::vector<std::uint8_t> pinned;    // 1: pinned (stays where it is until unpinned)
};

// A mass as the engine keeps it (MassReal). Throws std::invalid_argument where `mass` is not a
// positive finite number that single precision holds as a normal number (1.2e-38 to 3.4e38 kg).
MassReal toMass(Real mass);

}  // namespace drape::sim
