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

// What a substep of the force model is, worked out once as it begins (World::forceSubstep), as the
// position model's position::Substep is: every integrator's stage reads it.
struct Substep {
  Real h = 0.0;  // s
  Integrator integrator = Integrator::rk4;
  Real linearDamping = 0.0;  // 1/s: the global damping and the air's drag
  Vec3 acceleration{0.0};    // m/s^2: gravity + drag x the wind's velocity
  AirSettings air;           // its pressure on the triangles (wind pressure where > 0)
  // With colliders, a substep's motion is swept from where it started: the integrators that do not
  // keep the previous positions (all but Verlet) set them first.
  bool keepStart = false;
};
Substep makeSubstep(const WorldSettings& world, Real h);

// a(x, v) for every particle: gravity, global damping, air drag, wind pressure and every spring,
// divided by mass; zero for pinned particles.
void accelerations(const Cloth& cloth, const Substep& substep, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                   std::vector<Vec3>& a);

// Sizes the scratch the integrator needs and, for Verlet, starts its history (x_prev from the
// velocities by a Taylor step back).
void startHistory(Cloth& cloth, const Substep& substep, SolverScratch& scratch);
void step(Cloth& cloth, const Substep& substep, SolverScratch& scratch);

}  // namespace drape::sim::force
