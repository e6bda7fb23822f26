#include "contacts.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace drape::sim::contact {

namespace {

struct Candidate {
  int collider = -1;
  Vec3 normal{0.0};
  Real offset = 0.0;
};

// The contact plane, if the motion from `from` to `to` comes within `thickness` of the collider.
Candidate touch(const Collider& collider, int index, Vec3 from, Vec3 to, Real thickness) {
  const Vec3 motion = to - from;
  const Real travel = glm::length(motion);
  const Real reach = travel + 2.0 * thickness + 1e-6;
  const SurfaceDistance start = collider.distance(from, reach);
  if (start.distance >= reach) return {};
  if (start.distance < thickness) {
    // Already touching (resting contact, or a rounding-deep start): the surface nearest the end,
    // seen from the side the particle started on.
    const SurfaceDistance end = collider.distance(to, reach);
    if (collider.settings().shape == ColliderShape::mesh) {
      const Vec3 surface = from - start.normal * start.distance;
      return {index, start.normal, glm::dot(start.normal, surface) + thickness};
    }
    return {index, end.normal, glm::dot(end.normal, to) - end.distance + thickness};
  }
  // Sphere tracing: the distance bounds how far the segment can advance without meeting the surface.
  Real t = 0.0;
  SurfaceDistance here = start;
  for (int step = 0; step < 64 && travel > 0.0; ++step) {
    if (here.distance < thickness) {
      const Vec3 p = from + motion * t;
      const Vec3 surface = p - here.normal * here.distance;
      return {index, here.normal, glm::dot(here.normal, surface) + thickness};
    }
    t += std::max(here.distance - thickness * 0.5, thickness * 0.25) / travel;
    if (t > 1.0) break;
    here = collider.distance(from + motion * t, reach);
  }
  // The end point itself (the march may step past a surface it only grazes at the end).
  const SurfaceDistance end = collider.distance(to, reach);
  if (end.distance < thickness) return {index, end.normal, glm::dot(end.normal, to) - end.distance + thickness};
  return {};
}

}  // namespace

void detect(Cloth& cloth, const std::vector<Collider>& colliders, SolverScratch& scratch) {
  ParticleState& s = cloth.state;
  const std::size_t n = s.position.size();
  if (scratch.contactCollider.size() != n) {
    scratch.contactCollider.assign(n, -1);
    scratch.contactNormal.assign(n, Vec3{0.0});
    scratch.contactOffset.assign(n, 0.0);
    scratch.contactDepth.assign(n, 0.0);
  }
  const Real thickness = cloth.settings.thickness;
  for (std::size_t i = 0; i < n; ++i) {
    scratch.contactCollider[i] = -1;
    if (s.inverseMass[i] == 0.0) continue;
    Real deepest = -thickness;
    for (std::size_t c = 0; c < colliders.size(); ++c) {
      const Candidate candidate =
          touch(colliders[c], static_cast<int>(c), s.previousPosition[i], s.position[i], thickness);
      if (candidate.collider < 0) continue;
      const Real depth = candidate.offset - glm::dot(candidate.normal, s.position[i]);
      if (depth <= deepest) continue;
      deepest = depth;
      scratch.contactCollider[i] = candidate.collider;
      scratch.contactNormal[i] = candidate.normal;
      scratch.contactOffset[i] = candidate.offset;
    }
    scratch.contactDepth[i] = 0.0;
  }
  project(cloth, scratch);
}

void project(Cloth& cloth, SolverScratch& scratch) {
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < scratch.contactCollider.size(); ++i) {
    if (scratch.contactCollider[i] < 0) continue;
    const Real gap = glm::dot(scratch.contactNormal[i], s.position[i]) - scratch.contactOffset[i];
    if (gap < 0.0) {
      s.position[i] -= scratch.contactNormal[i] * gap;
      // Every push out counts, also those undoing what the constraints pulled in: the normal force
      // friction answers to includes the weight of the cloth hanging from this particle.
      scratch.contactDepth[i] -= gap;
    }
  }
}

void friction(Cloth& cloth, const std::vector<Collider>& colliders, Real h, const SolverScratch& scratch) {
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < scratch.contactCollider.size(); ++i) {
    const int c = scratch.contactCollider[i];
    const Real depth = scratch.contactDepth[i];
    if (c < 0 || depth <= 0.0) continue;
    const Vec3 n = scratch.contactNormal[i];
    if (glm::dot(n, s.position[i]) - scratch.contactOffset[i] > 1e-9) continue;  // lifted off
    const Friction& f = colliders[static_cast<std::size_t>(c)].settings().friction;
    const Vec3 relative = (s.position[i] - s.previousPosition[i]) -
                          colliders[static_cast<std::size_t>(c)].surfaceVelocity(s.position[i]) * h;
    const Vec3 tangential = relative - n * glm::dot(n, relative);
    const Real length = glm::length(tangential);
    if (length < f.staticCoefficient * depth) {
      s.position[i] -= tangential;
    } else if (length > 0.0) {
      s.position[i] -= tangential * std::min(f.kineticCoefficient * depth / length, 1.0);
    }
  }
}

void respondWithVelocities(Cloth& cloth, const std::vector<Collider>& colliders, Real h, SolverScratch& scratch) {
  detect(cloth, colliders, scratch);  // also projects the positions
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < scratch.contactCollider.size(); ++i) {
    const int c = scratch.contactCollider[i];
    if (c < 0) continue;
    const Collider& collider = colliders[static_cast<std::size_t>(c)];
    const Vec3 n = scratch.contactNormal[i];
    const Vec3 surface = collider.surfaceVelocity(s.position[i]);
    Vec3 relative = s.velocity[i] - surface;
    const Real approach = glm::dot(relative, n);
    if (approach < 0.0) {
      relative -= n * approach;  // inelastic: no velocity into the surface
      const Vec3 tangential = relative - n * glm::dot(relative, n);
      const Real length = glm::length(tangential);
      const Real impulse = -approach;
      if (length <= collider.settings().friction.staticCoefficient * impulse) {
        relative -= tangential;
      } else if (length > 0.0) {
        relative -= tangential * std::min(collider.settings().friction.kineticCoefficient * impulse / length, 1.0);
      }
      s.velocity[i] = surface + relative;
    }
    // Verlet keeps its velocity in x - x_prev.
    s.previousPosition[i] = s.position[i] - s.velocity[i] * h;
  }
}

void clampTravel(Cloth& cloth, Real maxTravel) {
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const Vec3 travel = s.position[i] - s.previousPosition[i];
    const Real length = glm::length(travel);
    if (length > maxTravel) s.previousPosition[i] = s.position[i] - travel * (maxTravel / length);
  }
}

void selfCollide(std::vector<Cloth>& cloths, const SelfCollisionSettings& settings, SelfCollisionScratch& scratch) {
  // Every particle of every cloth in one spatial hash (Teschner et al. 2003): cells of size d,
  // particles counting-sorted by cell hash, neighbours found in the 27 cells around each one.
  // Deterministic: particles are visited and stored in (cloth, index) order.
  scratch.owner.clear();
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    for (std::size_t i = 0; i < cloths[c].state.position.size(); ++i) {
      scratch.owner.push_back({static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)});
    }
  }
  const std::size_t n = scratch.owner.size();
  const Real d = settings.distance;
  const std::size_t tableSize = 2 * n + 1;
  const auto hashOf = [tableSize](glm::i64vec3 cell) {
    const auto h = static_cast<std::uint64_t>((cell.x * 92837111) ^ (cell.y * 689287499) ^ (cell.z * 283923481));
    return static_cast<std::size_t>(h % tableSize);
  };
  const auto cellOf = [d](Vec3 x) { return glm::i64vec3(glm::floor(x / d)); };
  const auto positionOf = [&cloths](const SelfCollisionScratch::Owner& o) -> Vec3& {
    return cloths[o.cloth].state.position[o.particle];
  };
  scratch.start.assign(tableSize + 1, 0);
  scratch.entries.resize(n);
  for (std::size_t k = 0; k < n; ++k) ++scratch.start[hashOf(cellOf(positionOf(scratch.owner[k]))) + 1];
  for (std::size_t k = 0; k < tableSize; ++k) scratch.start[k + 1] += scratch.start[k];
  scratch.fill.assign(scratch.start.begin(), scratch.start.end() - 1);
  for (std::size_t k = 0; k < n; ++k) {
    scratch.entries[scratch.fill[hashOf(cellOf(positionOf(scratch.owner[k])))]++] = static_cast<std::uint32_t>(k);
  }

  const Real d2 = d * d;
  for (std::size_t a = 0; a < n; ++a) {
    const auto [ca, i] = scratch.owner[a];
    ParticleState& si = cloths[ca].state;
    const glm::i64vec3 cell = cellOf(si.position[i]);
    for (int z = -1; z <= 1; ++z) {
      for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
          const std::size_t bucket = hashOf(cell + glm::i64vec3(x, y, z));
          for (std::uint32_t k = scratch.start[bucket]; k < scratch.start[bucket + 1]; ++k) {
            const std::uint32_t b = scratch.entries[k];
            if (b <= a) continue;
            const auto [cb, j] = scratch.owner[b];
            ParticleState& sj = cloths[cb].state;
            const Vec3 between = sj.position[j] - si.position[i];
            const Real distance2 = glm::dot(between, between);
            if (distance2 >= d2 || distance2 < 1e-24) continue;
            const Real wi = si.inverseMass[i], wj = sj.inverseMass[j];
            if (wi + wj == 0.0) continue;
            // Particles of one cloth closer than d at rest (neighbours) keep their rest distance.
            const Real target =
                ca == cb ? std::min(d, glm::length(cloths[ca].rest.restPositions[j] - cloths[ca].rest.restPositions[i]))
                         : d;
            const Real distance = std::sqrt(distance2);
            if (distance >= target) continue;
            const Vec3 push = between * ((target - distance) / (distance * (wi + wj)));
            si.position[i] -= push * wi;
            sj.position[j] += push * wj;
            // Cloth-cloth friction: move both velocities towards their mean.
            const Vec3 vi = si.position[i] - si.previousPosition[i], vj = sj.position[j] - sj.previousPosition[j];
            const Vec3 mean = (vi + vj) * 0.5;
            si.previousPosition[i] += (vi - mean) * settings.friction;
            sj.previousPosition[j] += (vj - mean) * settings.friction;
          }
        }
      }
    }
  }
}

}  // namespace drape::sim::contact
