#include "drape/bench/hang2.hpp"

namespace drape::bench {

sim::WorldSettings hang2(int n, const Hang2Solver& solver) {
  sim::WorldSettings world;
  world.solver.model = sim::Model::position;
  world.solver.dt = 1.0 / 60.0;
  world.solver.substeps = solver.substeps;
  world.solver.iterations = solver.iterations;
  world.solver.lines = solver.lines;
  world.solver.tethers = solver.tethers;
  world.solver.geometricStiffness = solver.geometricStiffness;
  world.solver.tethersBetweenSteps = solver.tethersBetweenSteps;
  world.solver.extraLineSteps = solver.extraLineSteps;
  world.solver.stretchTolerance = solver.stretchTolerance;
  world.gravity = {0.0, -9.81, 0.0};
  sim::ClothSettings cloth;
  cloth.lattice = {n, n, 1.0, 1.0, sim::Vec3{0.0, 1.5, 0.0}, sim::LatticePlane::xz};
  cloth.mass = 1.0;
  for (sim::ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = {1.0, 0.0, 0.0};
  cloth.pins = {{0, 0, std::nullopt}, {n - 1, 0, std::nullopt}};
  world.cloths.push_back(cloth);
  return world;
}

}  // namespace drape::bench
