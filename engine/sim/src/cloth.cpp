#include "drape/sim/cloth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

std::vector<Hinge> buildHinges(const ClothRest& rest) {
  struct Side {
    ParticleIndex low, high, opposite;
    bool operator<(const Side& o) const {
      return low != o.low ? low < o.low : high != o.high ? high < o.high : opposite < o.opposite;
    }
  };
  std::vector<Side> sides;
  sides.reserve(rest.triangles.size() * 3);
  for (const glm::uvec3& t : rest.triangles) {
    for (int k = 0; k < 3; ++k) {
      const ParticleIndex a = t[k], b = t[(k + 1) % 3];
      sides.push_back({std::min(a, b), std::max(a, b), t[(k + 2) % 3]});
    }
  }
  std::sort(sides.begin(), sides.end());
  // cot of the angle at p between q - p and r - p, and twice the triangle's area
  const auto cotangent = [](Vec3 p, Vec3 q, Vec3 r, Real& doubleArea) {
    const Vec3 u = q - p, v = r - p;
    doubleArea = glm::length(glm::cross(u, v));
    return glm::dot(u, v) / doubleArea;
  };
  std::vector<Hinge> hinges;
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i + 1;
    while (j < sides.size() && sides[j].low == sides[i].low && sides[j].high == sides[i].high) ++j;
    if (j - i == 2) {
      const Side& one = sides[i];
      const Side& other = sides[i + 1];
      const Vec3 x0 = rest.restPosition(one.low), x1 = rest.restPosition(one.high);
      const Vec3 x2 = rest.restPosition(one.opposite), x3 = rest.restPosition(other.opposite);
      Real a0 = 0.0, a1 = 0.0, unused = 0.0;
      const Real t0 = cotangent(x0, x1, x2, a0), t1 = cotangent(x1, x0, x2, unused);
      const Real f0 = cotangent(x0, x1, x3, a1), f1 = cotangent(x1, x0, x3, unused);
      const Real area = 0.5 * (a0 + a1);
      if (a0 > 0.0 && a1 > 0.0 && std::isfinite(t0 + t1 + f0 + f1) && area > 0.0) {
        const Real s = 1.0 / std::sqrt(area);
        // Rounded to single precision, the last is what makes the four sum to exactly 0: C then
        // does not change when the whole cloth moves, wherever it is.
        const RestReal k0 = static_cast<RestReal>((t1 + f1) * s), k1 = static_cast<RestReal>((t0 + f0) * s);
        const RestReal k2 = static_cast<RestReal>(-(t0 + t1) * s);
        hinges.push_back({{one.low, one.high, one.opposite, other.opposite}, {k0, k1, k2, -(k0 + k1 + k2)}});
      }
    }
    i = j;
  }
  return hinges;
}

}  // namespace drape::sim
