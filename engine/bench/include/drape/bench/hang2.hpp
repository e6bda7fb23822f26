// hang2, the standard benchmark scene: assets/scenes/hang2.json (built into the library), an N x N
// sheet, 1 m square in the x-z plane, 1 kg, pinned at corners (0, 0) and (N - 1, 0), with
// structural, shear and bend constraints (all rigid: stiffness 1), gravity, dt = 1/60 s, solved as
// the file says. The benchmark, the Google Benchmark harness and the tests all start from it.
#pragma once

#include <optional>

#include "drape/sim/settings.hpp"

namespace drape::bench {

// Where a case solves hang2 otherwise than the scene file: each field set replaces the file's
// solver key of that name (docs/scenes.md), each unset one keeps the file's.
struct Hang2Solver {
  std::optional<int> substeps;
  std::optional<int> iterations;
  std::optional<sim::StretchSolver> stretchSolver;
  std::optional<bool> tethers;
  std::optional<double> maxStretch;
};

// The scene file's hang2 at N x N (N from 2), with `solver`'s changes.
sim::WorldSettings hang2(int n, const Hang2Solver& solver = {});

}  // namespace drape::bench
