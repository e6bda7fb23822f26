// The position-based model: Verlet integration and iterative constraint satisfaction, as in the
// seed (Provot 1995; Jakobsen, "Advanced Character Physics", 2001).
#pragma once

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/settings.hpp"
#include "drape/sim/world.hpp"
#include "parallel/workers.hpp"
#include "part_clock.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::position {

// Verlet needs x_prev at t = -h. It is chosen so that the first step moves a free particle exactly
// as du/dt = a - k u, u(0) = v0 would (k = damping + drag, a = g + drag wind); since integrate() is
// exact for that equation step to step, the whole trajectory of a free particle is then exact.
// With k = 0 this is the Taylor start x_prev = x - v0 h + a h^2 / 2, which makes Verlet reproduce
// x0 + v0 t + a t^2 / 2; x_prev = x would start the cloth with a spurious velocity of a h / 2.
void startHistory(Cloth& cloth, Vec3 acceleration, Real k, Real h);

// Adds the aerodynamic force on every triangle to `acceleration` (zeroed first):
// f = pressure * area * ((wind - v) . n) n, shared equally by the triangle's three particles.
void accumulateWindPressure(const Cloth& cloth, const AirSettings& air, Real h, std::vector<Vec3>& acceleration);

// What a substep of the position model is, worked out once as it begins (World::positionSubstep)
// and read by its rows: the integrator's share of velocity kept and its reach, the constant
// acceleration; each cloth's compliances over h^2 follow from it as its constraints are projected
// (Compliances).
struct Substep {
  Real h = 0.0;            // s
  Real decay = 1.0;        // e^{-kh}, k = damping + drag: the share of its velocity a free particle keeps
  Real reach = 0.0;        // h^2 (1 - e^{-kh}) / (kh): how far a constant acceleration moves it, per m/s^2
  Vec3 acceleration{0.0};  // gravity + drag x the wind's velocity, m/s^2
};
Substep makeSubstep(const WorldSettings& world, Real h);

// x' = x + (x - x_prev) e^{-kh} + a h^2 (1 - e^{-kh}) / (kh),  k = damping + drag,
// a = g + drag wind + a_extra. With k = 0 this is the seed's Verlet step; with k > 0 it is the exact
// solution of du/dt = a - k u over the substep, so no damping or drag can make it overshoot and a
// falling particle reaches exactly the terminal velocity a / k. Pinned particles (inverse mass 0)
// do not move. With `keepPosition` each particle's position is also copied there as it was before
// the step (the guard's copy, made in the same pass).
void integrate(Cloth& cloth, const Substep& substep, const std::vector<Vec3>* extraAcceleration, Workers& workers,
               Vec3* keepPosition = nullptr);

// `solver.iterations` Gauss-Seidel sweeps over the stretch, shear and bend constraints, in the
// batches of scratch (batches.hpp; built for the cloth's current constraints). Each violated
// constraint is corrected as the seed writes it, weighted by inverse mass and scaled by the kind's
// stiffness k:  dx_a = k w_a / (w_a + w_b) (|x_b - x_a| - r) (x_b - x_a) / |x_b - x_a|,
//               dx_b = -k w_b / (w_a + w_b) (...)
// With equal masses and k = 1 that is exactly the seed's dx_1 = 1/2 (|x2 - x1| - r)(x2 - x1)/|x2 - x1|.
// Each sweep starts with the tethers (scratch.tethers), if any (and projects them again after each
// of the lines' Newton steps where solver.maxStretch says so). With `colliders`, the contact
// planes are re-enforced after every sweep, so the constraints cannot pull a particle back into a
// collider, and friction acts there too (contact::friction), so the next sweep sees a stuck particle stay. With
// solver.xpbd each kind resists with its compliance instead (see settings.hpp); with the lines stretch solver the
// stretch constraints are solved a line at a time (lines.hpp; scratch.lines built). Batches, lines and tethers are
// shared among the workers: the result does not depend on how many there are. Each part (tethers, each kind, the loose
// links, the contact planes) is timed by `parts`.
void projectConstraints(Cloth& cloth, const SolverSettings& solver, const Substep& substep, SolverScratch& scratch,
                        const std::vector<Collider>& colliders, Workers& workers, PartClock& parts);

// One more sweep of projectConstraints' kind, after self-contact pushed (World::positionSubstep):
// every constraint, then the contacts self-contact just pushed (scratch.layerContacts, now this
// substep's) held, then the collider contacts' planes. Nothing is reset: with XPBD the multipliers
// go on adding up, as over the substep's sweeps. (Self-contact then pushes its contacts again.)
void sweepAfterContacts(Cloth& cloth, const SolverSettings& solver, const Substep& substep, SolverScratch& scratch,
                        const std::vector<Collider>& colliders, Workers& workers, PartClock& parts);

// Removes the kind's damping fraction of the relative velocity along each constraint, by moving
// x_prev, conserving momentum. One after another, in the seed's sweep's order (scratch.sweepOrder,
// by particle pair) where the plan has one, else (lines) in the order the cloth keeps them.
void dampConstraints(Cloth& cloth, const SolverScratch& scratch);

// Which way an XPBD link moves its two particles (projectCompliant: the sweep, the shear and bend
// batches, the loose links; and the lines' solve): along its direction at the substep's start,
// n0 = (b0 - a0) / |b0 - a0|, instead of its direction now, n, as SHAKE does (Ryckaert, Ciccotti
// and Berendsen 1977). A push along n0 is a central force between where the particles were, so
// such moves keep the cloth's angular momentum, sum m x cross v with v = (x - x_prev) / h, exactly,
// however few the sweeps. Along n it shrinks a spinning cloth's momentum by 1 / sqrt(1 + (omega
// h)^2) a substep: 38 % in 5 s at a turn a second and 240 substeps a second. The multiplier is
// still found along n, so the move shortens the link by n . n0 of what it would along n: a little
// less, never more.
//
// But n0 takes the link's sideways pull from the substep's start, explicitly, and a taut link's
// sideways waves then grow once that pull is stiff against the particles' masses: its geometric
// stiffness |lambda| / l (lambda the link's multiplier so far this substep, its tension times h^2)
// times w_a + w_b is (omega h)^2 for its sideways swing. n0 serves while that is below
// kExplicitSwing; a taut link moves along n, implicitly (a spinning sheet's links are far below
// it, a hanging one's near its pins above). So does a link that has turned more than 60 degrees
// within the substep (a fold snapping through, a crumple, a hard contact), where n0 says little
// about how to shorten it. kExplicitSwing was scanned on a 3.125 mm cotton strip hanging at 10
// substeps x 2 sweeps with lines: with n0 everywhere (or below 10) it went from 4e-5 to 21 %
// strain; below 1 its bending length moved by 0.4 %, below 0.1 by 0.01 %.
inline constexpr Real kExplicitSwing = 0.1;
inline Vec3 alongStart(const Vec3& n, const Vec3& a0, const Vec3& b0, Real lambda, Real wSum, Real restLength) {
  if (!(std::abs(lambda) * wSum < kExplicitSwing * restLength)) return n;
  const Vec3 d0 = b0 - a0;
  const Real length02 = glm::dot(d0, d0);
  if (!(length02 > 1e-20)) return n;
  const Vec3 n0 = d0 * (1.0 / std::sqrt(length02));
  return glm::dot(n, n0) >= 0.5 ? n0 : n;
}

// One constraint with XPBD: alphaTilde = compliance / h^2, `lambda` its multiplier this substep,
// `start` the positions at the substep's start (the particles move along the link's direction
// there, which keeps angular momentum: position_model.cpp).
void projectCompliant(std::vector<Vec3>& position, const std::vector<Vec3>& start, const std::vector<Real>& inverseMass,
                      const DistanceConstraint& constraint, Real alphaTilde, Real& lambda);

// The nearest point to `point` within the particle's tethers (its pins' balls, those still pinned),
// as projectTethers would put the particle there; `point` itself for a particle with none.
Vec3 withinTethers(const ParticleState& s, const SolverScratch::Tethers& tethers, ParticleIndex particle, Vec3 point);

// One constraint, exposed for tests.
void projectDistance(std::vector<Vec3>& position, const std::vector<Real>& inverseMass,
                     const DistanceConstraint& constraint, Real stiffness);

}  // namespace drape::sim::position
