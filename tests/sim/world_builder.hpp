// Small settings builders for engine tests.
#pragma once

#include <vector>

#include "drape/sim/settings.hpp"
#include "drape/sim/world.hpp"

namespace drape::sim::test {

// A cloth of columns x rows with the given model's materials all switched off except stretch.
inline ClothSettings chainCloth(int columns, int rows, Real width, Real height, Real mass, Vec3 origin,
                                LatticePlane plane, KindMaterial stretch) {
  ClothSettings cloth;
  cloth.lattice = {columns, rows, width, height, origin, plane};
  cloth.mass = mass;
  cloth.material(ConstraintKind::stretch) = stretch;
  cloth.material(ConstraintKind::shear) = {0.0, 0.0};
  cloth.material(ConstraintKind::bend) = {0.0, 0.0};
  return cloth;
}

// A vertical spring: particle (0,0) pinned at `top`, particle (0,1) hanging `restLength` below it,
// each particle of mass `particleMass`.
inline WorldSettings verticalSpring(Model model, Integrator integrator, double dt, Real ks, Real particleMass,
                                    Real restLength = 1.0, Vec3 top = {0.0, 2.0, 0.0}) {
  WorldSettings world;
  world.solver.model = model;
  world.solver.integrator = integrator;
  world.solver.dt = dt;
  ClothSettings cloth = chainCloth(1, 2, 1.0, restLength, 2.0 * particleMass, top, LatticePlane::xy, {ks, 0.0});
  cloth.pins.push_back({0, 0, std::nullopt});
  world.cloths.push_back(cloth);
  return world;
}

inline WorldSettings singleParticle(Vec3 start) {
  WorldSettings world;
  ClothSettings cloth = chainCloth(1, 1, 1.0, 1.0, 1.0, start, LatticePlane::xz, {1.0, 0.0});
  world.cloths.push_back(cloth);
  return world;
}

// The two-corner hanging sheet, the seed's showcase.
inline WorldSettings hangingSheet(int n, int iterations, int substeps) {
  WorldSettings world;
  world.solver.iterations = iterations;
  world.solver.substeps = substeps;
  ClothSettings cloth;
  cloth.lattice = {n, n, 1.0, 1.0, Vec3{-0.5, 1.5, -0.5}, LatticePlane::xz};
  cloth.mass = 1.0;
  cloth.material(ConstraintKind::stretch) = {1.0, 0.0};
  cloth.material(ConstraintKind::shear) = {1.0, 0.0};
  cloth.material(ConstraintKind::bend) = {0.2, 0.0};
  cloth.pins = {{0, 0, std::nullopt}, {n - 1, 0, std::nullopt}};
  world.cloths.push_back(cloth);
  return world;
}

// Every particle's position, cloth after cloth, after `steps` steps on `threads` threads.
inline std::vector<Vec3> positionsAfter(WorldSettings settings, int threads, int steps) {
  World world(std::move(settings));
  world.setThreads(threads);
  world.run(steps);
  std::vector<Vec3> all;
  for (const Cloth& cloth : world.cloths())
    all.insert(all.end(), cloth.state.position.begin(), cloth.state.position.end());
  return all;
}

}  // namespace drape::sim::test
