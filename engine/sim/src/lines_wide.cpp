// The full Newton line step's elimination eight lines at a time: this file alone is built for AVX
// (engine/sim/CMakeLists.txt), and lines.cpp calls it only where the CPU has AVX.
#include "lines_wide.hpp"

#include "stiff_lanes.hpp"

namespace drape::sim::lines {

void solveStiffLanesWide(SolverScratch::StiffRows* rows, std::size_t n, const float* alphaTilde) {
  solveStiffLanes<Wide>(rows, n, load<Wide>(alphaTilde));
}

}  // namespace drape::sim::lines
