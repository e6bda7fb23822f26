// hang2, the standard benchmark scene: an N x N sheet, 1 m square in the x-z plane, 1 kg, pinned
// at corners (0, 0) and (N - 1, 0), with structural, shear and bend constraints (all rigid:
// stiffness 1), gravity, dt = 1/60 s.
#pragma once

#include "drape/sim/settings.hpp"

namespace drape::bench {

// How Drape solves it (the configuration the benchmark reports): tethers to the two pins, each
// row and column of stretch constraints solved at once with the links' geometric stiffness,
// `substeps` substeps of one sweep each; with tethersBetweenSteps the tethers are projected again
// after each of the line solve's two Newton steps. Up to extraLineSteps more steps a sweep where an
// edge is still over stretchTolerance.
struct Hang2Solver {
  int substeps = 2;
  int iterations = 1;
  bool lines = true;
  bool tethers = true;
  bool geometricStiffness = true;
  bool tethersBetweenSteps = false;
  int extraLineSteps = 4;
  double stretchTolerance = 0.04;
};

sim::WorldSettings hang2(int n, const Hang2Solver& solver = {});

}  // namespace drape::bench
