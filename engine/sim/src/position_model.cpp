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
    if (s.inverseMass[i] == 0.0) continue;
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

void projectConstraints(Cloth& cloth, int iterations, SolverScratch* contacts) {
  ParticleState& s = cloth.state;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (ConstraintKind kind : kConstraintKinds) {
      const Real stiffness = cloth.settings.material(kind).stiffness;
      if (stiffness == 0.0) continue;
      for (const DistanceConstraint& c : cloth.rest.of(kind)) projectDistance(s.position, s.inverseMass, c, stiffness);
    }
    if (contacts) contact::project(cloth, *contacts);
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
