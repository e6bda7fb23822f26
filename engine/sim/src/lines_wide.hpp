// The AVX build of the stiff line solve's elimination (lines_wide.cpp): call it only where the CPU
// has AVX (lines.cpp checks once).
#pragma once

#include <cstddef>

#include "drape/sim/state.hpp"

namespace drape::sim::lines {

// solveStiffLanes for all eight lanes of rows[0, n), alphaTilde one float per lane.
void solveStiffLanesWide(SolverScratch::StiffRows* rows, std::size_t n, const float* alphaTilde);

}  // namespace drape::sim::lines
