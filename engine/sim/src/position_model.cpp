#include "position_model.hpp"

#include <cmath>

#include <glm/geometric.hpp>

namespace drape::sim::position {

void startHistory(Cloth& cloth, Vec3 initialAcceleration, float h) {
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    s.previousPosition[i] = s.inverseMass[i] > 0.0f ? s.position[i] + 0.5f * initialAcceleration * h * h
                                                    : s.position[i];
  }
}

void accumulateWindPressure(const Cloth& cloth, const AirSettings& air, float h,
                            std::vector<Vec3>& acceleration) {
  const ParticleState& s = cloth.state;
  std::fill(acceleration.begin(), acceleration.end(), Vec3{0.0f});
  const float inverseH = 1.0f / h;
  for (const glm::uvec3& t : cloth.rest.triangles) {
    const Vec3 doubleAreaNormal = glm::cross(s.position[t.y] - s.position[t.x], s.position[t.z] - s.position[t.x]);
    const float doubleArea = glm::length(doubleAreaNormal);
    if (!(doubleArea > 0.0f)) continue;  // a degenerate triangle feels no pressure
    const Vec3 velocity = (s.position[t.x] - s.previousPosition[t.x] + s.position[t.y] -
                           s.previousPosition[t.y] + s.position[t.z] - s.previousPosition[t.z]) *
                          (inverseH / 3.0f);
    // pressure * area * (relative . n) n  with area = |N| / 2 and n = N / |N|
    const Vec3 force = doubleAreaNormal * (air.pressure * 0.5f * glm::dot(air.velocity - velocity, doubleAreaNormal) / doubleArea);
    for (int corner = 0; corner < 3; ++corner) {
      const ParticleIndex p = t[corner];
      acceleration[p] += force * (s.inverseMass[p] / 3.0f);
    }
  }
}

void integrate(Cloth& cloth, const WorldSettings& world, float h, const std::vector<Vec3>* extraAcceleration) {
  ParticleState& s = cloth.state;
  const float decay = std::exp(-(world.solver.damping + world.air.drag) * h);
  const Vec3 constantAcceleration = world.gravity + world.air.drag * world.air.velocity;
  const float h2 = h * h;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (s.inverseMass[i] == 0.0f) continue;
    Vec3 acceleration = constantAcceleration;
    if (extraAcceleration) acceleration += (*extraAcceleration)[i];
    const Vec3 x = s.position[i];
    s.position[i] = x + (x - s.previousPosition[i]) * decay + acceleration * h2;
    s.previousPosition[i] = x;
  }
}

void projectDistance(std::vector<Vec3>& position, const std::vector<float>& inverseMass,
                     const DistanceConstraint& c, float stiffness) {
  const float wa = inverseMass[c.a], wb = inverseMass[c.b];
  const float wSum = wa + wb;
  if (wSum == 0.0f) return;
  const Vec3 d = position[c.b] - position[c.a];
  const float length2 = glm::dot(d, d);
  // Coincident particles give no direction to push along; a later sweep, after the neighbours
  // have moved them apart, will.
  if (!(length2 > 1e-20f)) return;
  const float length = std::sqrt(length2);
  const Vec3 correction = d * (stiffness * (length - c.restLength) / (length * wSum));
  position[c.a] += wa * correction;
  position[c.b] -= wb * correction;
}

void projectConstraints(Cloth& cloth, int iterations) {
  ParticleState& s = cloth.state;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (ConstraintKind kind : kConstraintKinds) {
      const float stiffness = cloth.settings.material(kind).stiffness;
      if (stiffness == 0.0f) continue;
      for (const DistanceConstraint& c : cloth.rest.of(kind)) projectDistance(s.position, s.inverseMass, c, stiffness);
    }
  }
}

void dampConstraints(Cloth& cloth) {
  ParticleState& s = cloth.state;
  for (ConstraintKind kind : kConstraintKinds) {
    const float damping = cloth.settings.material(kind).damping;
    if (damping == 0.0f) continue;
    for (const DistanceConstraint& c : cloth.rest.of(kind)) {
      const float wa = s.inverseMass[c.a], wb = s.inverseMass[c.b];
      const float wSum = wa + wb;
      if (wSum == 0.0f) continue;
      const Vec3 d = s.position[c.b] - s.position[c.a];
      const float length = glm::length(d);
      if (!(length > 1e-10f)) continue;
      const Vec3 n = d / length;
      // relative displacement over the substep along n (velocity times h)
      const float relative = glm::dot((s.position[c.b] - s.previousPosition[c.b]) - (s.position[c.a] - s.previousPosition[c.a]), n);
      const float impulse = damping * relative / wSum;
      s.previousPosition[c.a] -= (wa * impulse) * n;
      s.previousPosition[c.b] += (wb * impulse) * n;
    }
  }
}

}  // namespace drape::sim::position
