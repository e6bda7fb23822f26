// The AVX build of the stiff line solve's elimination, and of its gather and scatter for eight
// neighbouring lines (lines_wide.cpp): call them only where the CPU has AVX (lines.cpp checks once).
#pragma once

#include <cstddef>
#include <cstdint>

#include "drape/sim/state.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::lines {

// solveStiffLanes for all eight lanes of rows[0, n), alphaTilde one float per lane.
void solveStiffLanesWide(SolverScratch::StiffRows* rows, std::size_t n, const float* alphaTilde);

// solveStiffLines' gather (lines.cpp) for eight lines whose particles at k are particle k of
// `first` (line 0's links, as lines.cpp's Line reads them) to it + 7 (a lattice's neighbouring
// columns, say), position holding x, y, z per particle: the same rows[0, n), bit for bit. links
// (for the rest lengths), lambda (null entries without XPBD) and tension: each line's.
void gatherConsecutiveWide(SolverScratch::StiffRows* rows, std::size_t n, const double* position,
                           const double* inverseMass, const float* mass, const DistanceConstraint* first,
                           const DistanceConstraint* const* links, const double* const* lambda,
                           const float* const* tension, const double* perUnitMass, double alphaTilde);
// ... and its scatter of the moves (the multipliers are the caller's): each particle free to move
// (inverse mass above 0) by yx * stiffness.
void scatterConsecutiveWide(const SolverScratch::StiffRows* rows, std::size_t n, double* position,
                            const double* inverseMass, const DistanceConstraint* first, double stiffness);

}  // namespace drape::sim::lines
