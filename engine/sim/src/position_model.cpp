#include "position_model.hpp"

#include "aerodynamics.hpp"
#include "contacts.hpp"

#include <cmath>

#include <glm/geometric.hpp>

namespace drape::sim::position {

namespace {
// (1 - e^{-kh}) / (kh), the weight of a constant acceleration in the damped Verlet step; 1 at k = 0.
Real relaxation(Real kh) { return kh > 0.0 ? -std::expm1(-kh) / kh : 1.0; }
}  // namespace

void startHistory(Cloth& cloth, Vec3 acceleration, Real k, Real h) {
  ParticleState& s = cloth.state;
  const Vec3 v0 = cloth.settings.initialVelocity;
  // Exact displacement over [0, h] of du/dt = a - k u, u(0) = v0: a h^2 / 2 + v0 h when k = 0.
  const Real kh = k * h;
  const Vec3 displacement = kh > 0.0 ? acceleration / k * h + (v0 - acceleration / k) * (h * relaxation(kh))
                                     : v0 * h + 0.5 * acceleration * h * h;
  // Choose x_prev so that the first step, x1 = x0 + (x0 - x_prev) e^{-kh} + a h^2 relaxation, moves exactly that far.
  const Vec3 back = (displacement - acceleration * (h * h * relaxation(kh))) * std::exp(kh);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    s.previousPosition[i] = s.inverseMass[i] > 0.0 ? s.position[i] - back : s.position[i];
  }
}

void accumulateWindPressure(const Cloth& cloth, const AirSettings& air, Real h, std::vector<Vec3>& acceleration) {
  const ParticleState& s = cloth.state;
  std::fill(acceleration.begin(), acceleration.end(), Vec3{0.0});
  const Real inverseH = 1.0 / h;
  addWindPressure(
      cloth.rest, s.position, s.inverseMass, air,
      [&](ParticleIndex p) { return (s.position[p] - s.previousPosition[p]) * inverseH; }, acceleration);
}

void integrate(Cloth& cloth, const WorldSettings& world, Real h, const std::vector<Vec3>* extraAcceleration) {
  ParticleState& s = cloth.state;
  // Exact for du/dt = a - k u over one substep: u' = u e^{-kh} + a h (1 - e^{-kh}) / (k h).
  const Real kh = (world.solver.damping + world.air.drag) * h;
  const Real decay = std::exp(-kh);
  const Real relaxed = relaxation(kh);
  const Vec3 constantAcceleration = world.gravity + world.air.drag * world.air.velocity;
  const Real h2 = h * h * relaxed;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (s.inverseMass[i] == 0.0) {
      // Pinned or held: no force moves it, only the world does. It carries on as it was set to move
      // (a finger sets x_prev one finger step behind); a pin has x_prev = x and stays exactly put.
      const Vec3 x = s.position[i];
      s.position[i] = x + (x - s.previousPosition[i]);
      s.previousPosition[i] = x;
      continue;
    }
    Vec3 acceleration = constantAcceleration;
    if (extraAcceleration) acceleration += (*extraAcceleration)[i];
    const Vec3 x = s.position[i];
    s.position[i] = x + (x - s.previousPosition[i]) * decay + acceleration * h2;
    s.previousPosition[i] = x;
  }
}

void projectDistance(std::vector<Vec3>& position, const std::vector<Real>& inverseMass, const DistanceConstraint& c,
                     Real stiffness) {
  const Real wa = inverseMass[c.a], wb = inverseMass[c.b];
  const Real wSum = wa + wb;
  if (wSum == 0.0) return;
  const Vec3 d = position[c.b] - position[c.a];
  const Real length2 = glm::dot(d, d);
  // Coincident particles give no direction to push along; a later sweep, after the neighbours
  // have moved them apart, will.
  if (!(length2 > 1e-20)) return;
  const Real length = std::sqrt(length2);
  const Vec3 correction = d * (stiffness * (length - c.restLength) / (length * wSum));
  position[c.a] += wa * correction;
  position[c.b] -= wb * correction;
}

namespace {

// XPBD (Macklin et al. 2016, eq. 18): with C = |x_b - x_a| - r and alpha~ = compliance / h^2,
// dlambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~), x_a -= w_a dlambda n, x_b += w_b dlambda n.
void projectCompliant(std::vector<Vec3>& position, const std::vector<Real>& inverseMass, const DistanceConstraint& c,
                      Real alphaTilde, Real& lambda) {
  const Real wa = inverseMass[c.a], wb = inverseMass[c.b];
  const Real denominator = wa + wb + alphaTilde;
  if (denominator == 0.0) return;
  const Vec3 d = position[c.b] - position[c.a];
  const Real length2 = glm::dot(d, d);
  if (!(length2 > 1e-20)) return;
  const Real length = std::sqrt(length2);
  const Real deltaLambda = (-(length - c.restLength) - alphaTilde * lambda) / denominator;
  lambda += deltaLambda;
  const Vec3 n = d / length;
  position[c.a] -= n * (wa * deltaLambda);
  position[c.b] += n * (wb * deltaLambda);
}

void projectTethers(ParticleState& s, const std::vector<SolverScratch::Tether>& tethers) {
  for (const SolverScratch::Tether& t : tethers) {
    // The anchor was let go, or a finger holds the particle (then the finger decides where it is).
    if (s.inverseMass[t.pin] != 0.0 || s.inverseMass[t.particle] == 0.0) continue;
    const Vec3 d = s.position[t.particle] - s.position[t.pin];
    const Real length = glm::length(d);
    if (length > t.length) s.position[t.particle] = s.position[t.pin] + d * (t.length / length);
  }
}

}  // namespace

void projectConstraints(Cloth& cloth, int iterations, Real h, bool xpbd, SolverScratch& scratch, bool contacts) {
  ParticleState& s = cloth.state;
  if (xpbd) {
    for (ConstraintKind kind : kConstraintKinds) {
      scratch.lambda[static_cast<std::size_t>(kind)].assign(cloth.rest.of(kind).size(), 0.0);
    }
  }
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (ConstraintKind kind : kConstraintKinds) {
      const KindMaterial& material = cloth.settings.material(kind);
      if (material.stiffness == 0.0) continue;
      const std::vector<DistanceConstraint>& constraints = cloth.rest.of(kind);
      if (xpbd) {
        const Real alphaTilde = material.compliance / (h * h);
        std::vector<Real>& lambda = scratch.lambda[static_cast<std::size_t>(kind)];
        for (std::size_t k = 0; k < constraints.size(); ++k) {
          projectCompliant(s.position, s.inverseMass, constraints[k], alphaTilde, lambda[k]);
        }
      } else {
        for (const DistanceConstraint& c : constraints)
          projectDistance(s.position, s.inverseMass, c, material.stiffness);
      }
    }
    if (!scratch.tethers.empty()) projectTethers(s, scratch.tethers);
    if (contacts) contact::project(cloth, scratch);
  }
}

void dampConstraints(Cloth& cloth) {
  ParticleState& s = cloth.state;
  for (ConstraintKind kind : kConstraintKinds) {
    const Real damping = cloth.settings.material(kind).damping;
    if (damping == 0.0) continue;
    for (const DistanceConstraint& c : cloth.rest.of(kind)) {
      const Real wa = s.inverseMass[c.a], wb = s.inverseMass[c.b];
      const Real wSum = wa + wb;
      if (wSum == 0.0) continue;
      const Vec3 d = s.position[c.b] - s.position[c.a];
      const Real length = glm::length(d);
      if (!(length > 1e-10)) continue;
      const Vec3 n = d / length;
      // relative displacement over the substep along n (velocity times h)
      const Real relative =
          glm::dot((s.position[c.b] - s.previousPosition[c.b]) - (s.position[c.a] - s.previousPosition[c.a]), n);
      const Real impulse = damping * relative / wSum;
      s.previousPosition[c.a] -= (wa * impulse) * n;
      s.previousPosition[c.b] += (wb * impulse) * n;
    }
  }
}

}  // namespace drape::sim::position
