#include "drape/sim/cloth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "drape/sim/settings.hpp"

namespace drape::sim {

std::string_view name(ConstraintKind kind) {
  switch (kind) {
    case ConstraintKind::stretch: return "stretch";
    case ConstraintKind::shear: return "shear";
    case ConstraintKind::bend: return "bend";
  }
  return "?";
}

std::string_view name(LatticePlane plane) {
  switch (plane) {
    case LatticePlane::xz: return "xz";
    case LatticePlane::xy: return "xy";
  }
  return "?";
}

RestReal toRestLength(Real length) {
  if (!(length >= 0.0 && length <= static_cast<Real>(std::numeric_limits<RestReal>::max()))) {
    throw std::invalid_argument("a rest length must be a finite number of metres, at most 3.4e38");
  }
  const auto rest = static_cast<RestReal>(length);
  if (length > 0.0 && rest == 0.0f) throw std::invalid_argument("a rest length must be at least 1.2e-38 m");
  return rest;
}

void ClothRest::setRestPositions(const std::vector<Vec3>& positions) {
  const Vec3 origin = positions.empty() ? Vec3{0.0} : positions.front();
  std::vector<glm::vec3> offsets(positions.size());
  constexpr auto kRange = static_cast<Real>(std::numeric_limits<float>::max());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3 offset = positions[i] - origin;
    // Written out so that a NaN fails it too.
    if (!(std::abs(offset.x) <= kRange && std::abs(offset.y) <= kRange && std::abs(offset.z) <= kRange)) {
      throw std::invalid_argument("rest position " + std::to_string(i) +
                                  " is not finite or lies beyond 3.4e38 m of the cloth's first particle");
    }
    offsets[i] = glm::vec3(offset);
  }
  restOrigin = origin;
  restOffsets = std::move(offsets);
}

RestReal toRestLengthAtLeast(Real length) {
  RestReal rest = toRestLength(length);
  if (static_cast<Real>(rest) < length) rest = std::nextafter(rest, std::numeric_limits<RestReal>::max());
  return rest;
}

namespace {

void addConstraint(ClothRest& rest, ConstraintKind kind, ParticleIndex a, ParticleIndex b) {
  const RestReal restLength = toRestLength(glm::length(rest.restPosition(b) - rest.restPosition(a)));
  // Lattice points are apart: they coincide only where the precision of the positions could not hold
  // the spacing. The message names the lattice's key the spacing comes from, as the reader spells it.
  if (restLength == 0.0f) {
    const bool sameRow = a / rest.columns == b / rest.columns, sameColumn = a % rest.columns == b % rest.columns;
    throw std::invalid_argument(std::string("grid.") +
                                (sameRow      ? "width"
                                 : sameColumn ? "height"
                                              : "width") +
                                ": the lattice spacing is too fine for the precision of its positions");
  }
  rest.constraints[static_cast<std::size_t>(kind)].push_back({a, b, restLength});
}

}  // namespace

ClothRest buildLattice(const LatticeSpec& spec, ConstraintSelection selection) {
  if (spec.columns < 1 || spec.rows < 1 || spec.columns > kMaxLatticeSide || spec.rows > kMaxLatticeSide ||
      static_cast<long long>(spec.columns) * spec.rows > kMaxParticles) {
    throw std::invalid_argument("lattice of " + std::to_string(spec.columns) + " x " + std::to_string(spec.rows) +
                                " particles is outside the limits");
  }
  if (!(spec.width > 0.0) || !(spec.height > 0.0) || !std::isfinite(spec.width) || !std::isfinite(spec.height)) {
    throw std::invalid_argument("lattice width and height must be positive");
  }

  ClothRest rest;
  rest.columns = spec.columns;
  rest.rows = spec.rows;
  const Real dx = spec.columns > 1 ? spec.width / static_cast<Real>(spec.columns - 1) : 0.0;
  const Real dy = spec.rows > 1 ? spec.height / static_cast<Real>(spec.rows - 1) : 0.0;
  // Unit vectors of the lattice's column and row directions in the world.
  const Vec3 along{1.0, 0.0, 0.0};
  const Vec3 down = spec.plane == LatticePlane::xz ? Vec3{0.0, 0.0, 1.0} : Vec3{0.0, -1.0, 0.0};

  std::vector<Vec3> positions;
  positions.reserve(static_cast<std::size_t>(spec.columns) * spec.rows);
  for (int row = 0; row < spec.rows; ++row) {
    for (int column = 0; column < spec.columns; ++column) {
      positions.push_back(spec.origin + along * (dx * static_cast<Real>(column)) +
                          down * (dy * static_cast<Real>(row)));
    }
  }
  // Rest lengths below come from the rounded positions, so that they agree with everything else
  // measured at rest (tethers, self-collision distances).
  rest.setRestPositions(positions);

  // Triangles wound counter-clockwise when seen from +y (xz plane) or +z (xy plane).
  for (int row = 0; row + 1 < spec.rows; ++row) {
    for (int column = 0; column + 1 < spec.columns; ++column) {
      const ParticleIndex p00 = rest.index(column, row), p10 = rest.index(column + 1, row);
      const ParticleIndex p01 = rest.index(column, row + 1), p11 = rest.index(column + 1, row + 1);
      if (spec.plane == LatticePlane::xz) {
        rest.triangles.push_back({p00, p01, p10});
        rest.triangles.push_back({p10, p01, p11});
      } else {
        rest.triangles.push_back({p00, p01, p11});
        rest.triangles.push_back({p00, p11, p10});
      }
    }
  }

  for (int row = 0; row < spec.rows; ++row) {
    for (int column = 0; column < spec.columns; ++column) {
      const ParticleIndex p = rest.index(column, row);
      if (selection.stretch) {
        if (column + 1 < spec.columns) addConstraint(rest, ConstraintKind::stretch, p, rest.index(column + 1, row));
        if (row + 1 < spec.rows) addConstraint(rest, ConstraintKind::stretch, p, rest.index(column, row + 1));
      }
      if (selection.shear && column + 1 < spec.columns && row + 1 < spec.rows) {
        addConstraint(rest, ConstraintKind::shear, p, rest.index(column + 1, row + 1));
        addConstraint(rest, ConstraintKind::shear, rest.index(column + 1, row), rest.index(column, row + 1));
      }
      if (selection.bend) {
        if (column + 2 < spec.columns) addConstraint(rest, ConstraintKind::bend, p, rest.index(column + 2, row));
        if (row + 2 < spec.rows) addConstraint(rest, ConstraintKind::bend, p, rest.index(column, row + 2));
      }
    }
  }
  return rest;
}

Real triangleArea(const ClothRest& rest, const glm::uvec3& t) {
  const Vec3 a = rest.restPosition(t[0]);
  return 0.5 * glm::length(glm::cross(rest.restPosition(t[1]) - a, rest.restPosition(t[2]) - a));
}

std::vector<Real> particleAreas(const ClothRest& rest) {
  std::vector<Real> area(rest.particleCount(), 0.0);
  for (const glm::uvec3& t : rest.triangles) {
    const Real a = triangleArea(rest, t);
    for (int k = 0; k < 3; ++k) area[t[k]] += a / 3.0;
  }
  return area;
}

std::vector<BendStencil> buildBendStencils(const ClothRest& rest) {
  const std::size_t n = rest.particleCount();
  const std::vector<Real> area = particleAreas(rest);
  // Each particle's stretch links, in the order the cloth lists them (deterministic).
  std::vector<std::uint32_t> start(n + 1, 0);
  const std::vector<DistanceConstraint>& links = rest.of(ConstraintKind::stretch);
  for (const DistanceConstraint& c : links) {
    ++start[c.a + 1];
    ++start[c.b + 1];
  }
  for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<ParticleIndex> other(start[n]);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (const DistanceConstraint& c : links) {
    other[fill[c.a]++] = c.b;
    other[fill[c.b]++] = c.a;
  }
  // By particle, not by the links' order (which planning changes with the thread count).
  for (std::size_t i = 0; i < n; ++i) std::sort(other.begin() + start[i], other.begin() + start[i + 1]);
  constexpr Real kOpposite = -0.99;  // cos 172 degrees
  std::vector<BendStencil> stencils;
  std::vector<bool> taken;  // of the particle's links, those on a line already
  for (std::size_t i = 0; i < n; ++i) {
    if (!(area[i] > 0.0)) continue;
    const Vec3 x = rest.restPosition(i);
    BendStencil stencil{};
    stencil.v.fill(static_cast<ParticleIndex>(i));
    stencil.k.fill(0.0f);
    Real coefficient[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    int used = 1, lines = 0;
    taken.assign(start[i + 1] - start[i], false);
    for (std::uint32_t p = start[i]; p < start[i + 1] && lines < 2; ++p) {
      if (taken[p - start[i]]) continue;
      const Vec3 da = rest.restPosition(other[p]) - x;
      const Real la = glm::length(da);
      if (!(la > 0.0)) continue;
      // The most nearly opposite link not yet taken.
      std::optional<std::uint32_t> found;
      Real bestCosine = kOpposite;
      for (std::uint32_t q = p + 1; q < start[i + 1]; ++q) {
        if (taken[q - start[i]]) continue;
        const Vec3 db = rest.restPosition(other[q]) - x;
        const Real lb = glm::length(db);
        if (!(lb > 0.0)) continue;
        const Real cosine = glm::dot(da, db) / (la * lb);
        if (cosine < bestCosine) {
          bestCosine = cosine;
          found = q;
        }
      }
      if (!found) continue;
      const std::uint32_t best = *found;
      taken[p - start[i]] = taken[best - start[i]] = true;
      const Real lb = glm::length(rest.restPosition(other[best]) - x);
      const Real scale = std::sqrt(area[i]) * 2.0 / (la + lb);
      stencil.v[used] = other[p];
      coefficient[used++] = scale / la;
      stencil.v[used] = other[best];
      coefficient[used++] = scale / lb;
      ++lines;
    }
    if (lines == 0) continue;
    // Rounded to single precision, k[0] is what makes them sum to exactly 0.
    float sum = 0.0f;
    for (int j = 1; j < 5; ++j) {
      stencil.k[j] = static_cast<RestReal>(coefficient[j]);
      sum += stencil.k[j];
    }
    stencil.k[0] = -sum;
    stencils.push_back(stencil);
  }
  return stencils;
}

}  // namespace drape::sim
