// The force-based model: the seed's mass-spring-damper cloth, integrated by the classical schemes.
// It exists to compare, to teach, and to show where stiff springs blow up; the position model is
// the default.
#pragma once

#include "drape/sim/settings.hpp"
#include "drape/sim/state.hpp"
#include "drape/sim/world.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::force {

// The seed's spring-damper force on particle 1 of a pair, with dx = x1 - x2 and dv = v1 - v2:
//   f1 = -[ks (|dx| - r) + kd (dv . dx) / |dx|] dx / |dx|,   f2 = -f1.
// Returns zero for coincident particles, which define no direction.
Vec3 springForce(Vec3 x1, Vec3 x2, Vec3 v1, Vec3 v2, Real restLength, Real ks, Real kd);

// a(x, v) for every particle: gravity, global damping, air drag, wind pressure and every spring,
// divided by mass; zero for pinned particles.
void accelerations(const Cloth& cloth, const WorldSettings& world, const std::vector<Vec3>& x,
                   const std::vector<Vec3>& v, std::vector<Vec3>& a);

void startHistory(Cloth& cloth, const WorldSettings& world, Real h, SolverScratch& scratch);
void step(Integrator integrator, Cloth& cloth, const WorldSettings& world, Real h, SolverScratch& scratch);

}  // namespace drape::sim::force
