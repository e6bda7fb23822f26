// Wind pressure on triangles, shared by both models.
#pragma once

#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/cloth.hpp"
#include "drape/sim/settings.hpp"

namespace drape::sim {

// Adds to `acceleration` the force of the moving air on every triangle,
//   f = pressure * area * ((wind - v) . n) n,
// with v the mean velocity of its corners (`velocityOf(particle)`) and n its unit normal, shared
// equally by its three particles. A degenerate triangle has no normal and feels no pressure.
template <typename VelocityOf>
void addWindPressure(const ClothRest& rest, const std::vector<Vec3>& x, const std::vector<Real>& inverseMass,
                     const AirSettings& air, VelocityOf velocityOf, std::vector<Vec3>& acceleration) {
  for (const glm::uvec3& t : rest.triangles) {
    const Vec3 doubleAreaNormal = glm::cross(x[t.y] - x[t.x], x[t.z] - x[t.x]);  // N = 2 area n
    const Real doubleArea = glm::length(doubleAreaNormal);
    if (!(doubleArea > 0.0)) continue;
    const Vec3 velocity = (velocityOf(t.x) + velocityOf(t.y) + velocityOf(t.z)) / 3.0;
    // area (relative . n) n = (relative . N) N / (2 |N|)
    const Vec3 force =
        doubleAreaNormal * (air.pressure * 0.5 * glm::dot(air.velocity - velocity, doubleAreaNormal) / doubleArea);
    for (int corner = 0; corner < 3; ++corner) acceleration[t[corner]] += force * (inverseMass[t[corner]] / 3.0);
  }
}

}  // namespace drape::sim
