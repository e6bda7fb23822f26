#include "drape/sim/metrics.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include <glm/geometric.hpp>

namespace drape::sim {

StrainStats structuralStrain(const World& world) {
  StrainStats stats;
  stats.max = -1.0;
  double sumAbs = 0.0;
  for (const Cloth& cloth : world.cloths()) {
    for (const DistanceConstraint& c : cloth.rest.of(ConstraintKind::stretch)) {
      if (!(c.restLength > 0.0)) continue;
      const double strain =
          static_cast<double>(glm::length(cloth.state.position[c.b] - cloth.state.position[c.a])) / c.restLength - 1.0;
      stats.max = std::max(stats.max, strain);
      sumAbs += std::abs(strain);
      ++stats.count;
    }
  }
  if (stats.count == 0) {
    stats.max = 0.0;
    return stats;
  }
  stats.mean = sumAbs / static_cast<double>(stats.count);
  return stats;
}

std::uint64_t stateHash(const World& world) {
  std::uint64_t hash = 14695981039346656037ull;
  const auto mix = [&](std::uint64_t word) {
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (word >> (8 * byte)) & 0xff;
      hash *= 1099511628211ull;
    }
  };
  mix(static_cast<std::uint64_t>(world.stepCount()));
  for (const Cloth& cloth : world.cloths()) {
    mix(cloth.state.position.size());
    for (const auto* array : {&cloth.state.position, &cloth.state.previousPosition}) {
      for (const Vec3& x : *array) {
        for (int axis = 0; axis < 3; ++axis) mix(std::bit_cast<std::uint64_t>(x[axis]));
      }
    }
  }
  return hash;
}

Vec3 centreOfMass(const Cloth& cloth) {
  Vec3 sum{0.0};
  double mass = 0.0;
  for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
    sum += static_cast<double>(cloth.state.mass[i]) * cloth.state.position[i];
    mass += cloth.state.mass[i];
  }
  return mass > 0.0 ? sum / mass : Vec3{0.0};
}

Momentum momentum(const World& world) {
  Momentum p;
  double mass = 0.0;
  Vec3 weighted{0.0};
  const auto free = [&](const auto& visit) {
    for (std::size_t c = 0; c < world.cloths().size(); ++c) {
      const ParticleState& s = world.cloths()[c].state;
      for (std::size_t i = 0; i < s.position.size(); ++i) {
        if (s.inverseMass[i] > 0.0)
          visit(static_cast<double>(s.mass[i]), s.position[i],
                world.velocity(static_cast<int>(c), static_cast<ParticleIndex>(i)));
      }
    }
  };
  free([&](double m, const Vec3& x, const Vec3& v) {
    mass += m;
    weighted += m * x;
    p.linear += m * v;
  });
  if (!(mass > 0.0)) return p;
  p.centre = weighted / mass;
  free([&](double m, const Vec3& x, const Vec3& v) { p.angular += m * glm::cross(x - p.centre, v); });
  return p;
}

Energy energy(const World& world) {
  Energy e;
  const Vec3 g = world.settings().gravity;
  for (std::size_t c = 0; c < world.cloths().size(); ++c) {
    const Cloth& cloth = world.cloths()[c];
    for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
      if (cloth.state.inverseMass[i] == 0.0) continue;  // pinned or held: moved by the world, no energy of its own
      const double m = cloth.state.mass[i];
      const Vec3 v = world.velocity(static_cast<int>(c), static_cast<ParticleIndex>(i));
      e.kinetic += 0.5 * m * static_cast<double>(glm::dot(v, v));
      e.gravitational -= m * static_cast<double>(glm::dot(g, cloth.state.position[i]));
    }
    if (world.settings().solver.model != Model::force) continue;
    for (ConstraintKind kind : kConstraintKinds) {
      const double ks = cloth.settings.material(kind).stiffness;
      for (const DistanceConstraint& con : cloth.rest.of(kind)) {
        const double stretch =
            static_cast<double>(glm::length(cloth.state.position[con.b] - cloth.state.position[con.a])) -
            con.restLength;
        e.elastic += 0.5 * ks * stretch * stretch;
      }
    }
  }
  return e;
}

std::vector<Vec3> vertexNormals(const Cloth& cloth) {
  std::vector<Vec3> normals;
  vertexNormals(cloth, normals);
  return normals;
}

void vertexNormals(const Cloth& cloth, std::vector<Vec3>& normals) {
  const std::vector<Vec3>& x = cloth.state.position;
  normals.assign(x.size(), Vec3{0.0});
  for (const glm::uvec3& t : cloth.rest.triangles) {
    const Vec3 n = glm::cross(x[t.y] - x[t.x], x[t.z] - x[t.x]);  // length = twice the area
    normals[t.x] += n;
    normals[t.y] += n;
    normals[t.z] += n;
  }
  const Vec3 planeNormal = cloth.settings.lattice.plane == LatticePlane::xz ? Vec3{0.0, 1.0, 0.0} : Vec3{0.0, 0.0, 1.0};
  for (Vec3& n : normals) {
    const Real length = glm::length(n);
    n = length > 0.0 ? n / length : planeNormal;
  }
}

}  // namespace drape::sim
