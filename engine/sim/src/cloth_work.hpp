// What a world keeps for one cloth alone, beside the cloth in its record (ClothRecord): the
// solver's plan and working arrays, which of its particles fingers hold, and the guard's copy of
// its positions. Internal to the engine.
#pragma once

#include <cstdint>
#include <vector>

#include "drape/sim/types.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim {

struct ClothWork {
  SolverScratch solver;
  // Per particle: 1 while a finger holds it. Empty until a finger first holds some of the cloth: a
  // scene no finger touches does not pay a byte a particle for it.
  std::vector<std::uint8_t> held;
  // The positions before the current step, where the guard keeps a copy (World::GuardCopy).
  std::vector<Vec3> lastGood;

  bool isHeld(std::size_t particle) const { return !held.empty() && held[particle] != 0; }
};

}  // namespace drape::sim
