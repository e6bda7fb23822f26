// The AVX build of a batch's distance projections (distance_wide.cpp): call it only where the CPU
// has AVX (cpuHasAvx, lines.hpp). It is the position model's projectDistance four constraints at a
// time, and gives the same bits.
#pragma once

#include <cstddef>

#include "drape/sim/cloth.hpp"

namespace drape::sim::position {

// projectDistance for constraints [begin, end) of one batch (no two share a particle), four at a
// time; position holds x, y, z per particle. Returns where it stopped: the last (end - begin) % 4
// constraints are left to the caller.
std::size_t projectBatchWide(double* position, const double* inverseMass, const DistanceConstraint* constraints,
                             std::size_t begin, std::size_t end, double stiffness);

}  // namespace drape::sim::position
