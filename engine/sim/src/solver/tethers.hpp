// Which pins each particle is tethered to (solver.tethers, Kim, Chentanez and Mueller 2012).
//
// A particle is tied to the pins of its piece nearest to it at rest, at most
// kMaxTethersPerParticle of them. Tying every particle to every pin cost memory and time in the
// product of the two counts (a 512 x 512 sheet with its top row pinned: 2.15 GB and 8.5 s a step);
// the nearest pins are the ones whose tethers bind, as a farther pin's ball mostly contains the
// nearer ones'. A cloth with no more pins than that in a piece is tied to all of them, as before.
#pragma once

#include <vector>

#include "drape/sim/state.hpp"
#include "drape/sim/world.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim {

inline constexpr std::size_t kMaxTethersPerParticle = 4;

// The tethers of every particle that is not pinned, sorted by particle, each particle's by pin
// index; lengths are the rest distances rounded up to a float (the rest shape lies within every
// tether). Time about (particles + pins) log, whatever the pins' layout on a lattice.
std::vector<SolverScratch::Tethers::Tether> nearestPinTethers(const Cloth& cloth);

}  // namespace drape::sim
