// The position-based model: Verlet integration and iterative constraint satisfaction, as in the
// seed (Provot 1995; Jakobsen, "Advanced Character Physics", 2001).
#pragma once

#include <vector>

#include "drape/sim/settings.hpp"
#include "drape/sim/world.hpp"
#include "workers.hpp"

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

// x' = x + (x - x_prev) e^{-kh} + a h^2 (1 - e^{-kh}) / (kh),  k = damping + drag,
// a = g + drag wind + a_extra. With k = 0 this is the seed's Verlet step; with k > 0 it is the exact
// solution of du/dt = a - k u over the substep, so no damping or drag can make it overshoot and a
// falling particle reaches exactly the terminal velocity a / k. Pinned particles (inverse mass 0)
// do not move. With `keepPosition` each particle's position is also copied there as it was before
// the step (the guard's copy, made in the same pass).
void integrate(Cloth& cloth, const WorldSettings& world, Real h, const std::vector<Vec3>* extraAcceleration,
               Workers& workers, Vec3* keepPosition = nullptr);

// `solver.iterations` Gauss-Seidel sweeps over the stretch, shear and bend constraints, in the
// batches of scratch (batches.hpp; built for the cloth's current constraints). Each violated
// constraint is corrected as the seed writes it, weighted by inverse mass and scaled by the kind's
// stiffness k:  dx_a = k w_a / (w_a + w_b) (|x_b - x_a| - r) (x_b - x_a) / |x_b - x_a|,
//               dx_b = -k w_b / (w_a + w_b) (...)
// With equal masses and k = 1 that is exactly the seed's dx_1 = 1/2 (|x2 - x1| - r)(x2 - x1)/|x2 - x1|.
// Each sweep starts with the tethers (scratch.tethers), if any (and projects them again after each
// of the lines' Newton steps with solver.tethersBetweenSteps). With `contacts`, the contact
// planes are re-enforced after every sweep, so the constraints cannot pull a particle back into a
// collider. With solver.xpbd each kind resists with its compliance instead (see settings.hpp); with
// solver.lines the stretch constraints are solved a line at a time (lines.hpp; scratch.lines
// built). Batches, lines and tethers are shared among the workers: the result does not depend on
// how many there are.
void projectConstraints(Cloth& cloth, const SolverSettings& solver, Real h, SolverScratch& scratch, bool contacts,
                        Workers& workers);

// Removes the kind's damping fraction of the relative velocity along each constraint, by moving
// x_prev, conserving momentum.
void dampConstraints(Cloth& cloth);

// One constraint with XPBD: alphaTilde = compliance / h^2, `lambda` its multiplier this substep.
void projectCompliant(std::vector<Vec3>& position, const std::vector<Real>& inverseMass,
                      const DistanceConstraint& constraint, Real alphaTilde, Real& lambda);

// One constraint, exposed for tests.
void projectDistance(std::vector<Vec3>& position, const std::vector<Real>& inverseMass,
                     const DistanceConstraint& constraint, Real stiffness);

}  // namespace drape::sim::position
