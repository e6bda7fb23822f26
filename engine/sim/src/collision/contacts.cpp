#include "collision/contacts.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace drape::sim::contact {

namespace {

struct Candidate {
  int collider = -1;
  Vec3 normal{0.0};
  Real offset = 0.0;
};

// The contact plane, if the motion from `from` to `to` comes within `near` (twice the thickness) of
// the collider. The plane itself lies `thickness` off the surface: a particle is pushed only if
// the sweeps take it closer than that. The margin is for what the sweeps do after the inertial
// motion: a particle resting on a ball that the last substep's push left moving outwards predicts a
// path that stays clear of the skin, and the cloth's pull then took it 0.37 mm into it unopposed;
// found there the next substep and pushed out, it flipped 0.3-0.6 mm every substep forever.
Candidate touch(const Collider& collider, int index, Vec3 previous, Vec3 to, Real thickness) {
  const Vec3 from = collider.carried(previous);  // in the collider's frame, the particle came from here
  const Vec3 motion = to - from;
  const Real travel = glm::length(motion);
  const Real near = 2.0 * thickness;
  const Real reach = travel + 2.0 * near + 1e-6;
  const SurfaceDistance start = collider.distance(from, reach);
  if (start.distance >= reach) return {};
  const auto planeThrough = [&](Vec3 p, const SurfaceDistance& d) {
    return Candidate{index, d.normal, glm::dot(d.normal, p - d.normal * d.distance) + thickness};
  };
  if (start.distance < near) {
    // Touching or all but (resting contact): keep to the side it started on. The surface nearest the
    // end serves while it faces the same way; past the middle of a thin solid it would be the far
    // face, and would push the particle out underneath.
    const SurfaceDistance end = collider.distance(to, reach);
    if (collider.settings().shape != ColliderShape::mesh && end.distance < near &&
        glm::dot(end.normal, start.normal) > 0.0) {
      return planeThrough(to, end);
    }
    return planeThrough(from, start);
  }
  // Sphere tracing: the distance bounds how far the segment can advance without meeting the surface.
  Real t = 0.0;
  SurfaceDistance here = start;
  while (travel > 0.0) {
    if (here.distance < near) return planeThrough(from + motion * t, here);
    t += std::max(std::max(here.distance - thickness * 0.5, thickness * 0.25) / travel, 1.0 / 256.0);
    // Also ends a march that met a NaN: a motion near the double range (a particle flung 1e307 m)
    // overflows its length to inf, and the distance at a point of it can be inf - inf.
    if (!(t <= 1.0)) break;
    here = collider.distance(from + motion * t, reach);
  }
  // The end point itself (the march may step past a surface it only grazes at the end).
  const SurfaceDistance end = collider.distance(to, reach);
  if (end.distance < near) return planeThrough(to, end);
  return {};
}

// Each free particle's contact is its own: the loops below go to the workers in blocks of
// particles, the same bit for bit whatever their number. Below the grain (particles a thread) a
// loop runs on the caller alone: the projection is a handful of operations a particle, detecting
// a march along its path. (No workers: the caller alone.)
constexpr std::size_t kDetectGrain = 256, kProjectGrain = 2048, kFrictionGrain = 1024;
template <class F>
void eachParticle(Workers* workers, std::size_t n, std::size_t grain, F&& f) {
  if (!workers) {
    f(std::size_t{0}, n);
    return;
  }
  workers->run(
      n, [&](std::size_t begin, std::size_t end, int) { f(begin, end); }, grain);
}

}  // namespace

void detect(Cloth& cloth, const std::vector<Collider>& colliders, SolverScratch& scratch, Workers* workers) {
  ParticleState& s = cloth.state;
  const std::size_t n = s.position.size();
  if (scratch.contactCollider.size() != n) {
    scratch.contactCollider.assign(n, -1);
    scratch.contactNormal.assign(n, Vec3{0.0});
    scratch.contactOffset.assign(n, 0.0);
    scratch.contactDepth.assign(n, 0.0);
    scratch.contactRub.assign(n, Vec3{0.0});
  }
  const Real thickness = cloth.settings.thickness;
  eachParticle(workers, n, kDetectGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      scratch.contactCollider[i] = -1;
      if (s.inverseMass[i] == 0.0) continue;
      Real deepest = -std::numeric_limits<Real>::infinity();
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
      scratch.contactRub[i] = Vec3{0.0};
    }
  });
  project(cloth, scratch, workers);
}

void project(Cloth& cloth, SolverScratch& scratch, Workers* workers) {
  ParticleState& s = cloth.state;
  eachParticle(workers, scratch.contactCollider.size(), kProjectGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (scratch.contactCollider[i] < 0) continue;
      const Real gap = glm::dot(scratch.contactNormal[i], s.position[i]) - scratch.contactOffset[i];
      if (gap < 0.0) {
        s.position[i] -= scratch.contactNormal[i] * gap;
        // Every push out counts, also those undoing what the constraints pulled in: the normal force
        // friction answers to includes the weight of the cloth hanging from this particle.
        scratch.contactDepth[i] -= gap;
      }
    }
  });
}

void friction(Cloth& cloth, const std::vector<Collider>& colliders, Real h, SolverScratch& scratch, Workers* workers) {
  ParticleState& s = cloth.state;
  eachParticle(workers, scratch.contactCollider.size(), kFrictionGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const int c = scratch.contactCollider[i];
      const Real depth = scratch.contactDepth[i];
      if (c < 0 || depth <= 0.0) continue;
      const Vec3 n = scratch.contactNormal[i];
      if (glm::dot(n, s.position[i]) - scratch.contactOffset[i] > 1e-9) continue;  // lifted off
      const Friction& f = colliders[static_cast<std::size_t>(c)].settings().friction;
      const Vec3 relative = (s.position[i] - s.previousPosition[i]) -
                            colliders[static_cast<std::size_t>(c)].surfaceVelocity(s.position[i]) * h;
      const Vec3 tangential = relative - n * glm::dot(n, relative);
      // The friction so far is part of that motion: without it the particle would have moved `free`.
      Vec3& rub = scratch.contactRub[i];
      const Vec3 free = tangential - rub;
      const Real length = glm::length(free);
      Vec3 next{0.0};  // the friction's whole correction this substep, after this call
      if (length < f.staticCoefficient * depth) {
        next = -free;  // stuck: back where the substep began, relative to the surface
      } else if (length > 0.0) {
        next = free * -std::min(f.kineticCoefficient * depth / length, Real{1.0});
      }
      s.position[i] += next - rub;
      rub = next;
    }
  });
}

void respondWithVelocities(Cloth& cloth, const std::vector<Collider>& colliders, Real h, SolverScratch& scratch) {
  detect(cloth, colliders, scratch);  // also projects the positions
  ParticleState& s = cloth.state;
  for (std::size_t i = 0; i < scratch.contactCollider.size(); ++i) {
    const int c = scratch.contactCollider[i];
    if (c < 0) continue;
    const Collider& collider = colliders[static_cast<std::size_t>(c)];
    const Vec3 n = scratch.contactNormal[i];
    if (glm::dot(n, s.position[i]) - scratch.contactOffset[i] > 1e-9) continue;  // passing by, not touching
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
    if (s.inverseMass[i] == 0.0) continue;  // a finger or pin moves it, as fast as it likes
    const Vec3 travel = s.position[i] - s.previousPosition[i];
    const Real length = glm::length(travel);
    if (length > maxTravel) s.previousPosition[i] = s.position[i] - travel * (maxTravel / length);
  }
}

void selfCollide(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings, SelfCollisionScratch& scratch,
                 Workers& workers) {
  // Every particle of every cloth in one spatial hash (Teschner et al. 2003): cells of size d,
  // particles counting-sorted by cell hash, neighbours found in the 27 cells around each one.
  // Two phases: the pairs in neighbouring cells are listed (in parallel, each thread its own run of
  // particles), then pushed apart one after another in that order, each at its distance then.
  // Deterministic whatever the number of threads: particles are visited in (cloth, index) order
  // and the lists are joined in the order of their runs.
  scratch.owner.clear();
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    for (std::size_t i = 0; i < cloths[c].cloth.state.position.size(); ++i) {
      scratch.owner.push_back({static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)});
    }
  }
  const std::size_t n = scratch.owner.size();
  const Real d = settings.distance;
  // A power of two at least 2n: the hash is masked, not divided.
  const std::size_t tableSize = std::bit_ceil(2 * n + 1);
  // Wrapping unsigned arithmetic: no overflow whatever the cell. Positions are finite and within
  // 1e6 m (the guard), and clamped so the cell always fits.
  const auto hashOf = [mask = tableSize - 1](glm::u64vec3 cell) {
    const std::uint64_t h = (cell.x * 92837111u) ^ (cell.y * 689287499u) ^ (cell.z * 283923481u);
    return static_cast<std::size_t>((h ^ (h >> 29)) & mask);
  };
  const auto positionOf = [&cloths](const SelfCollisionScratch::Owner& o) -> Vec3& {
    return cloths[o.cloth].cloth.state.position[o.particle];
  };
  scratch.cell.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    scratch.cell[k] =
        glm::u64vec3(glm::i64vec3(glm::floor(glm::clamp(positionOf(scratch.owner[k]), -2.0e6, 2.0e6) / d)));
  }
  scratch.start.assign(tableSize + 1, 0);
  scratch.entries.resize(n);
  for (std::size_t k = 0; k < n; ++k) ++scratch.start[hashOf(scratch.cell[k]) + 1];
  for (std::size_t k = 0; k < tableSize; ++k) scratch.start[k + 1] += scratch.start[k];
  scratch.fill.assign(scratch.start.begin(), scratch.start.end() - 1);
  for (std::size_t k = 0; k < n; ++k) {
    scratch.entries[scratch.fill[hashOf(scratch.cell[k])]++] = static_cast<std::uint32_t>(k);
  }

  scratch.pairs.resize(static_cast<std::size_t>(workers.threads()));
  for (std::vector<SelfCollisionScratch::Pair>& pairs : scratch.pairs) pairs.clear();
  workers.run(
      n,
      [&](std::size_t begin, std::size_t end, int thread) {
        std::vector<SelfCollisionScratch::Pair>& pairs = scratch.pairs[static_cast<std::size_t>(thread)];
        for (std::size_t a = begin; a < end; ++a) {
          for (int z = -1; z <= 1; ++z) {
            for (int y = -1; y <= 1; ++y) {
              for (int x = -1; x <= 1; ++x) {
                const glm::u64vec3 cell = scratch.cell[a] + glm::u64vec3(glm::i64vec3(x, y, z));
                const std::size_t bucket = hashOf(cell);
                for (std::uint32_t k = scratch.start[bucket]; k < scratch.start[bucket + 1]; ++k) {
                  const std::uint32_t b = scratch.entries[k];
                  // Each particle once: it is in one cell, and cells sharing a bucket are told apart.
                  if (b > a && scratch.cell[b] == cell) pairs.push_back({static_cast<std::uint32_t>(a), b});
                }
              }
            }
          }
        }
      },
      128);

  const Real d2 = d * d;
  for (const std::vector<SelfCollisionScratch::Pair>& pairs : scratch.pairs) {
    for (const auto [a, b] : pairs) {
      const auto [ca, i] = scratch.owner[a];
      const auto [cb, j] = scratch.owner[b];
      ParticleState& si = cloths[ca].cloth.state;
      ParticleState& sj = cloths[cb].cloth.state;
      const Vec3 between = sj.position[j] - si.position[i];
      const Real distance2 = glm::dot(between, between);
      if (distance2 >= d2 || distance2 < 1e-24) continue;
      const Real wi = si.inverseMass[i], wj = sj.inverseMass[j];
      if (wi + wj == 0.0) continue;
      // Particles of one cloth closer than d at rest (neighbours) keep their rest distance.
      const Real target =
          ca == cb
              ? std::min(d, glm::length(cloths[ca].cloth.rest.restPosition(j) - cloths[ca].cloth.rest.restPosition(i)))
              : d;
      const Real distance = std::sqrt(distance2);
      if (distance >= target) continue;
      const Vec3 push = between * ((target - distance) / (distance * (wi + wj)));
      si.position[i] -= push * wi;
      sj.position[j] += push * wj;
      // Cloth-cloth friction: remove `friction` of the pair's relative velocity, shared by inverse
      // mass (momentum is kept; a pinned particle takes none).
      const Vec3 relative = (si.position[i] - si.previousPosition[i]) - (sj.position[j] - sj.previousPosition[j]);
      const Vec3 change = relative * (settings.friction / (wi + wj));
      si.previousPosition[i] += change * wi;
      sj.previousPosition[j] -= change * wj;
    }
  }
}

}  // namespace drape::sim::contact
