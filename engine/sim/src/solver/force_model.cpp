#include "solver/force_model.hpp"

#include "solver/aerodynamics.hpp"

#include <glm/geometric.hpp>

namespace drape::sim::force {

Vec3 springForce(Vec3 x1, Vec3 x2, Vec3 v1, Vec3 v2, Real restLength, Real ks, Real kd) {
  const Vec3 dx = x1 - x2;
  const Real length = glm::length(dx);
  if (!(length > 1e-10)) return Vec3{0.0};
  const Vec3 direction = dx / length;
  return -(ks * (length - restLength) + kd * glm::dot(v1 - v2, direction)) * direction;
}

Substep makeSubstep(const WorldSettings& world, Real h) {
  Substep substep;
  substep.h = h;
  substep.integrator = world.solver.integrator;
  substep.linearDamping = world.solver.damping + world.air.drag;
  substep.acceleration = world.gravity + world.air.drag * world.air.velocity;
  substep.air = world.air;
  substep.keepStart = substep.integrator != Integrator::verlet && !world.colliders.empty();
  return substep;
}

void accelerations(const Cloth& cloth, const Substep& substep, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                   std::vector<Vec3>& a) {
  const std::vector<Real>& w = cloth.state.inverseMass;
  const AirSettings& air = substep.air;
  const Real linearDamping = substep.linearDamping;
  const Vec3 constant = substep.acceleration;
  // External accelerations first (a = f / m with f proportional to m), then forces times 1/m.
  for (std::size_t i = 0; i < x.size(); ++i) {
    a[i] = w[i] > 0.0 ? constant - linearDamping * v[i] : Vec3{0.0};
  }
  if (air.pressure > 0.0) {
    addWindPressure(
        cloth.rest, x, w, air, [&](ParticleIndex p) { return v[p]; }, a);
  }
  for (ConstraintKind kind : kConstraintKinds) {
    const KindMaterial& material = cloth.settings.material(kind);
    if (material.stiffness == 0.0 && material.damping == 0.0) continue;
    for (const DistanceConstraint& c : cloth.rest.of(kind)) {
      const Vec3 f = springForce(x[c.a], x[c.b], v[c.a], v[c.b], c.restLength, material.stiffness, material.damping);
      a[c.a] += w[c.a] * f;
      a[c.b] -= w[c.b] * f;
    }
  }
}

namespace {

void resize(std::vector<Vec3>& array, std::size_t n) { array.assign(n, Vec3{0.0}); }

void explicitEuler(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const Real h = substep.h;
  ParticleState& s = cloth.state;
  accelerations(cloth, substep, s.position, s.velocity, scratch.acceleration);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    s.position[i] += s.velocity[i] * h;
    s.velocity[i] += scratch.acceleration[i] * h;
  }
}

void symplecticEuler(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const Real h = substep.h;
  ParticleState& s = cloth.state;
  accelerations(cloth, substep, s.position, s.velocity, scratch.acceleration);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    s.velocity[i] += scratch.acceleration[i] * h;
    s.position[i] += s.velocity[i] * h;
  }
}

// Stormer-Verlet on positions; velocity-dependent forces see the backward difference (x - x_prev)/h.
void verlet(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const Real h = substep.h;
  ParticleState& s = cloth.state;
  const Real inverseH = 1.0 / h;
  for (std::size_t i = 0; i < s.position.size(); ++i)
    s.velocity[i] = (s.position[i] - s.previousPosition[i]) * inverseH;
  accelerations(cloth, substep, s.position, s.velocity, scratch.acceleration);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const Vec3 x = s.position[i];
    s.position[i] = 2.0 * x - s.previousPosition[i] + scratch.acceleration[i] * (h * h);
    s.previousPosition[i] = x;
    s.velocity[i] = (s.position[i] - x) * inverseH;
  }
}

void midpoint(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const Real h = substep.h;
  ParticleState& s = cloth.state;
  const std::size_t n = s.position.size();
  accelerations(cloth, substep, s.position, s.velocity, scratch.acceleration);
  for (std::size_t i = 0; i < n; ++i) {
    scratch.trialPosition[i] = s.position[i] + s.velocity[i] * (0.5 * h);
    scratch.trialVelocity[i] = s.velocity[i] + scratch.acceleration[i] * (0.5 * h);
  }
  accelerations(cloth, substep, scratch.trialPosition, scratch.trialVelocity, scratch.acceleration);
  for (std::size_t i = 0; i < n; ++i) {
    s.position[i] += scratch.trialVelocity[i] * h;
    s.velocity[i] += scratch.acceleration[i] * h;
  }
}

// Classical RK4 on the first-order system (x, v)' = (v, a(x, v)), keeping running sums so only
// five scratch arrays are needed.
void rk4(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const Real h = substep.h;
  ParticleState& s = cloth.state;
  const std::size_t n = s.position.size();
  std::vector<Vec3>& a = scratch.acceleration;
  std::vector<Vec3>& xt = scratch.trialPosition;
  std::vector<Vec3>& vt = scratch.trialVelocity;
  accelerations(cloth, substep, s.position, s.velocity, a);  // k1
  for (std::size_t i = 0; i < n; ++i) {
    scratch.sumPosition[i] = s.velocity[i];
    scratch.sumVelocity[i] = a[i];
    xt[i] = s.position[i] + s.velocity[i] * (0.5 * h);
    vt[i] = s.velocity[i] + a[i] * (0.5 * h);
  }
  accelerations(cloth, substep, xt, vt, a);  // k2
  for (std::size_t i = 0; i < n; ++i) {
    scratch.sumPosition[i] += 2.0 * vt[i];
    scratch.sumVelocity[i] += 2.0 * a[i];
    xt[i] = s.position[i] + vt[i] * (0.5 * h);
    vt[i] = s.velocity[i] + a[i] * (0.5 * h);
  }
  accelerations(cloth, substep, xt, vt, a);  // k3
  for (std::size_t i = 0; i < n; ++i) {
    scratch.sumPosition[i] += 2.0 * vt[i];
    scratch.sumVelocity[i] += 2.0 * a[i];
    xt[i] = s.position[i] + vt[i] * h;
    vt[i] = s.velocity[i] + a[i] * h;
  }
  accelerations(cloth, substep, xt, vt, a);  // k4
  for (std::size_t i = 0; i < n; ++i) {
    s.position[i] += (scratch.sumPosition[i] + vt[i]) * (h / 6.0);
    s.velocity[i] += (scratch.sumVelocity[i] + a[i]) * (h / 6.0);
  }
}

}  // namespace

void startHistory(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  const std::size_t n = cloth.state.position.size();
  const Real h = substep.h;
  resize(scratch.acceleration, n);
  const Integrator integrator = substep.integrator;
  if (integrator == Integrator::midpoint || integrator == Integrator::rk4) {
    resize(scratch.trialPosition, n);
    resize(scratch.trialVelocity, n);
  }
  if (integrator == Integrator::rk4) {
    resize(scratch.sumPosition, n);
    resize(scratch.sumVelocity, n);
  }
  if (integrator != Integrator::verlet) return;
  // Taylor start, as in the position model: x_prev = x - v0 h + a0 h^2 / 2.
  ParticleState& s = cloth.state;
  accelerations(cloth, substep, s.position, s.velocity, scratch.acceleration);
  for (std::size_t i = 0; i < n; ++i) {
    s.previousPosition[i] = s.position[i] - s.velocity[i] * h + scratch.acceleration[i] * (0.5 * h * h);
  }
}

void step(Cloth& cloth, const Substep& substep, SolverScratch& scratch) {
  // Collisions sweep each particle's motion from where the step started (Verlet keeps it anyway).
  if (substep.keepStart) cloth.state.previousPosition = cloth.state.position;
  switch (substep.integrator) {
    case Integrator::explicitEuler: explicitEuler(cloth, substep, scratch); break;
    case Integrator::symplecticEuler: symplecticEuler(cloth, substep, scratch); break;
    case Integrator::verlet: verlet(cloth, substep, scratch); break;
    case Integrator::midpoint: midpoint(cloth, substep, scratch); break;
    case Integrator::rk4: rk4(cloth, substep, scratch); break;
  }
}

}  // namespace drape::sim::force
