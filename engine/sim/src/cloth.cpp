#include "drape/sim/cloth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/common.hpp>
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

// A lattice whose spacing single precision cannot hold where its particles lie: the first pair of
// neighbours that coincide at rest names the lattice's key the spacing comes from, as the reader
// spells it.
[[noreturn]] void latticeTooFine(const ClothRest& rest) {
  const auto key = [&]() -> const char* {
    const auto same = [&](ParticleIndex a, ParticleIndex b) { return rest.restOffsets[a] == rest.restOffsets[b]; };
    for (int row = 0; row < rest.rows; ++row) {
      for (int column = 0; column < rest.columns; ++column) {
        const ParticleIndex p = rest.index(column, row);
        if (column + 1 < rest.columns && same(p, rest.index(column + 1, row))) return "width";
        if (row + 1 < rest.rows && same(p, rest.index(column, row + 1))) return "height";
      }
    }
    return "width";
  };
  throw std::invalid_argument(std::string("grid.") + key() +
                              ": the lattice spacing is too fine for the precision of its positions");
}

}  // namespace

ClothRest constrainMesh(const LatticeMesh& mesh, ConstraintSelection selection) {
  const std::size_t n = mesh.positions.size();
  if (mesh.nodes.size() != n) throw std::invalid_argument("a mesh needs one lattice node (or none) per particle");
  ClothRest rest;
  rest.setRestPositions(mesh.positions);  // before the rest lengths, which come from the rounded positions
  rest.triangles.reserve(mesh.triangles.size());
  for (const glm::uvec3& t : mesh.triangles) {
    if (t.x >= n || t.y >= n || t.z >= n || t.x == t.y || t.y == t.z || t.z == t.x) {
      throw std::invalid_argument("a mesh triangle has a corner out of range or twice");
    }
    rest.triangles.push_back(t);
  }
  rest.constraints = meshConstraints(rest, rest.triangles, mesh.nodes, selection);
  orderConstraints(rest);
  return rest;
}

std::array<std::vector<DistanceConstraint>, kConstraintKindCount> meshConstraints(
    const ClothRest& rest, const std::vector<glm::uvec3>& triangles, const std::vector<glm::ivec2>& nodes,
    ConstraintSelection selection) {
  const std::size_t n = rest.particleCount();
  std::array<std::vector<DistanceConstraint>, kConstraintKindCount> constraints;
  if (nodes.size() != n) throw std::invalid_argument("a mesh needs one lattice node (or none) per particle");

  // Nodes by (row, column), for finding a particle by its lattice position.
  struct Node {
    int row, column;
    ParticleIndex particle;
    bool operator<(const Node& o) const { return row != o.row ? row < o.row : column < o.column; }
  };
  std::vector<Node> byNode;
  for (std::size_t p = 0; p < n; ++p) {
    const glm::ivec2 node = nodes[p];
    if (node == kNoNode) continue;
    if (node.x < 0 || node.y < 0) throw std::invalid_argument("a mesh node has a negative column or row");
    byNode.push_back({node.y, node.x, static_cast<ParticleIndex>(p)});
  }
  std::sort(byNode.begin(), byNode.end());
  for (std::size_t i = 1; i < byNode.size(); ++i) {
    if (!(byNode[i - 1] < byNode[i])) throw std::invalid_argument("two particles of a mesh stand for one lattice node");
  }
  const auto at = [&](int column, int row) -> std::optional<ParticleIndex> {
    const auto found = std::lower_bound(byNode.begin(), byNode.end(), Node{row, column, 0});
    if (found == byNode.end() || found->row != row || found->column != column) return std::nullopt;
    return found->particle;
  };
  const auto onLattice = [&](ParticleIndex p) { return nodes[p] != kNoNode; };

  // Edges as (low << 32 | high), sorted: the triangles', or a chain's lattice neighbours.
  const auto key = [](ParticleIndex a, ParticleIndex b) {
    return static_cast<std::uint64_t>(std::min(a, b)) << 32 | std::max(a, b);
  };
  std::vector<std::uint64_t> edges;
  if (!triangles.empty()) {
    edges.reserve(triangles.size() * 3);
    for (const glm::uvec3& t : triangles) {
      for (int k = 0; k < 3; ++k) edges.push_back(key(t[k], t[(k + 1) % 3]));
    }
  } else {
    for (const Node& node : byNode) {
      for (const auto next : {at(node.column + 1, node.row), at(node.column, node.row + 1)}) {
        if (next) edges.push_back(key(node.particle, *next));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const auto isEdge = [&](ParticleIndex a, ParticleIndex b) {
    return std::binary_search(edges.begin(), edges.end(), key(a, b));
  };

  const auto add = [&](ConstraintKind kind, ParticleIndex a, ParticleIndex b) {
    const RestReal restLength = toRestLength(glm::length(rest.restPosition(b) - rest.restPosition(a)));
    if (restLength > 0.0f) constraints[static_cast<std::size_t>(kind)].push_back({a, b, restLength});
  };

  // Stretch: every edge but a cell's diagonals; the diagonals, by cell and which: (row, column, 0 for
  // (column, row)-(column + 1, row + 1), 1 for (column + 1, row)-(column, row + 1)).
  std::vector<std::array<int, 3>> diagonals;
  for (const std::uint64_t edge : edges) {
    const auto a = static_cast<ParticleIndex>(edge >> 32), b = static_cast<ParticleIndex>(edge & 0xffffffffu);
    if (onLattice(a) && onLattice(b)) {
      const glm::ivec2 d = nodes[b] - nodes[a];
      if (std::abs(d.x) == 1 && std::abs(d.y) == 1) {
        const glm::ivec2 low = glm::min(nodes[a], nodes[b]);
        diagonals.push_back({low.y, low.x, d.x == d.y ? 0 : 1});
        continue;
      }
    }
    if (selection.stretch) add(ConstraintKind::stretch, a, b);
  }
  if (selection.shear) {
    // A whole cell: two triangles within it that leave out opposite corners; its other diagonal too.
    std::vector<std::array<int, 3>> corners;  // (row, column of the cell, corner left out: 0 1 / 2 3)
    for (const glm::uvec3& t : triangles) {
      if (!onLattice(t.x) || !onLattice(t.y) || !onLattice(t.z)) continue;
      const glm::ivec2 a = nodes[t.x], b = nodes[t.y], c = nodes[t.z];
      const glm::ivec2 low = glm::min(a, glm::min(b, c)), high = glm::max(a, glm::max(b, c));
      if (high.x - low.x != 1 || high.y - low.y != 1) continue;
      int missing = 0 + 1 + 2 + 3;
      for (const glm::ivec2& v : {a, b, c}) missing -= (v.y - low.y) * 2 + (v.x - low.x);
      corners.push_back({low.y, low.x, missing});
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
      const auto& [row, column, missing] = corners[i];
      const auto& next = corners[i + 1];
      if (next[0] != row || next[1] != column || missing + next[2] != 3) continue;
      // Left out 0 and 3 (a split along 1-2, the anti-diagonal): the main diagonal too; else the anti.
      diagonals.push_back({row, column, missing == 0 ? 0 : 1});
    }
    std::sort(diagonals.begin(), diagonals.end());
    diagonals.erase(std::unique(diagonals.begin(), diagonals.end()), diagonals.end());
    for (const auto& [row, column, which] : diagonals) {
      const auto p00 = at(column, row), p11 = at(column + 1, row + 1);
      const auto p10 = at(column + 1, row), p01 = at(column, row + 1);
      if (which == 0 && p00 && p11) add(ConstraintKind::shear, *p00, *p11);
      if (which == 1 && p10 && p01) add(ConstraintKind::shear, *p10, *p01);
    }
  }
  if (selection.bend) {
    for (const Node& node : byNode) {
      for (const auto& [dc, dr] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const auto middle = at(node.column + dc, node.row + dr), end = at(node.column + 2 * dc, node.row + 2 * dr);
        if (middle && end && isEdge(node.particle, *middle) && isEdge(*middle, *end) && !isEdge(node.particle, *end)) {
          add(ConstraintKind::bend, node.particle, *end);
        }
      }
    }
  }
  return constraints;
}

ClothRest buildLattice(const LatticeSpec& spec, ConstraintSelection selection) {
  if (spec.columns < 1 || spec.rows < 1 || spec.columns > kMaxLatticeSide || spec.rows > kMaxLatticeSide ||
      static_cast<long long>(spec.columns) * spec.rows > kMaxParticles) {
    throw std::invalid_argument("lattice of " + std::to_string(spec.columns) + " x " + std::to_string(spec.rows) +
                                " particles is outside the limits");
  }
  if (!(spec.width > 0.0) || !(spec.height > 0.0) || !std::isfinite(spec.width) || !std::isfinite(spec.height)) {
    throw std::invalid_argument("lattice width and height must be positive");
  }

  LatticeMesh mesh;
  const Real dx = spec.columns > 1 ? spec.width / static_cast<Real>(spec.columns - 1) : 0.0;
  const Real dy = spec.rows > 1 ? spec.height / static_cast<Real>(spec.rows - 1) : 0.0;
  mesh.spacing = spec.columns > 1 ? (spec.rows > 1 ? std::min(dx, dy) : dx) : dy;
  // Unit vectors of the lattice's column and row directions in the world.
  const Vec3 along{1.0, 0.0, 0.0};
  const Vec3 down = spec.plane == LatticePlane::xz ? Vec3{0.0, 0.0, 1.0} : Vec3{0.0, -1.0, 0.0};
  const auto count = static_cast<std::size_t>(spec.columns) * static_cast<std::size_t>(spec.rows);
  mesh.positions.reserve(count);
  mesh.nodes.reserve(count);
  for (int row = 0; row < spec.rows; ++row) {
    for (int column = 0; column < spec.columns; ++column) {
      mesh.positions.push_back(spec.origin + along * (dx * static_cast<Real>(column)) +
                               down * (dy * static_cast<Real>(row)));
      mesh.nodes.push_back({column, row});
    }
  }
  // Triangles wound counter-clockwise when seen from +y (xz plane) or +z (xy plane).
  const auto index = [&](int column, int row) { return static_cast<ParticleIndex>(row * spec.columns + column); };
  for (int row = 0; row + 1 < spec.rows; ++row) {
    for (int column = 0; column + 1 < spec.columns; ++column) {
      const ParticleIndex p00 = index(column, row), p10 = index(column + 1, row);
      const ParticleIndex p01 = index(column, row + 1), p11 = index(column + 1, row + 1);
      if (spec.plane == LatticePlane::xz) {
        mesh.triangles.push_back({p00, p01, p10});
        mesh.triangles.push_back({p10, p01, p11});
      } else {
        mesh.triangles.push_back({p00, p01, p11});
        mesh.triangles.push_back({p00, p11, p10});
      }
    }
  }
  ClothRest rest = constrainMesh(mesh, selection);
  rest.columns = spec.columns;
  rest.rows = spec.rows;
  // Every neighbour pair joined, unless single precision could not hold the spacing somewhere.
  const auto columns = static_cast<std::size_t>(spec.columns), rows = static_cast<std::size_t>(spec.rows);
  const std::size_t stretch = (columns - 1) * rows + columns * (rows - 1);
  const std::size_t shear = 2 * (columns - 1) * (rows - 1);
  const std::size_t bend = (columns > 2 ? (columns - 2) * rows : 0) + (rows > 2 ? columns * (rows - 2) : 0);
  if (rest.of(ConstraintKind::stretch).size() != (selection.stretch ? stretch : 0) ||
      rest.of(ConstraintKind::shear).size() != (selection.shear ? shear : 0) ||
      rest.of(ConstraintKind::bend).size() != (selection.bend ? bend : 0)) {
    latticeTooFine(rest);
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

namespace {

// The cotangent of the angle at corner o between the edges to p and q (at rest): infinite where
// the triangle is degenerate.
Real cotangentAt(const Vec3& o, const Vec3& p, const Vec3& q) {
  const Vec3 a = p - o, b = q - o;
  const Real sine = glm::length(glm::cross(a, b));
  return sine > 0.0 ? glm::dot(a, b) / sine : std::numeric_limits<Real>::infinity();
}

// How thin a triangle may be for its cotangents to count: an angle of about a degree.
constexpr Real kMostCotangent = 57.0;

}  // namespace

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
  // By particle, not by the order the links are kept in.
  for (std::size_t i = 0; i < n; ++i) std::sort(other.begin() + start[i], other.begin() + start[i + 1]);
  // Each particle's triangles, in the order the cloth lists them.
  std::vector<std::uint32_t> triangleStart(n + 1, 0);
  for (const glm::uvec3& t : rest.triangles) {
    for (int k = 0; k < 3; ++k) ++triangleStart[t[k] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) triangleStart[i + 1] += triangleStart[i];
  std::vector<std::uint32_t> around(triangleStart[n]);
  std::vector<std::uint32_t> triangleFill(triangleStart.begin(), triangleStart.end() - 1);
  for (std::uint32_t t = 0; t < rest.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) around[triangleFill[rest.triangles[t][k]]++] = t;
  }
  // Particle i's cotangent Laplacian, sqrt(A) / (2 A) sum_j w_j (x_j - x_i), into (neighbour,
  // weight), by neighbour; false unless i's triangles go round it once, each turned the same way
  // (each neighbour the first corner after i of one triangle and the second of another, and the
  // walk from one to the next closing only after all of them): a particle on a border, where two
  // fans meet, or under a doubled triangle has no one Laplacian. False too where a triangle is too
  // thin for its cotangents, or the neighbours with a weight are more than a stencil holds. Weights
  // that come to exactly 0 (a square cell's diagonal) are left out.
  std::vector<std::pair<ParticleIndex, Real>> weights;
  std::vector<std::pair<ParticleIndex, ParticleIndex>> fan;  // each triangle's corners after i
  const auto cotangentStencil = [&](std::size_t i) {
    weights.clear();
    fan.clear();
    const Vec3 x = rest.restPosition(i);
    for (std::uint32_t a = triangleStart[i]; a < triangleStart[i + 1]; ++a) {
      const glm::uvec3& t = rest.triangles[around[a]];
      const int c = t[0] == i ? 0 : t[1] == i ? 1 : 2;
      const ParticleIndex p = t[(c + 1) % 3], q = t[(c + 2) % 3];
      const Vec3 xp = rest.restPosition(p), xq = rest.restPosition(q);
      // The edge i-p is opposite q's corner, the edge i-q opposite p's.
      const Real atQ = cotangentAt(xq, x, xp), atP = cotangentAt(xp, x, xq);
      if (!(std::abs(atQ) <= kMostCotangent) || !(std::abs(atP) <= kMostCotangent)) return false;
      weights.push_back({p, atQ});
      weights.push_back({q, atP});
      fan.push_back({p, q});
    }
    if (fan.empty()) return false;
    // Once round: from the first triangle's p, each step to the q of the triangle whose p it is.
    ParticleIndex at = fan[0].first;
    for (std::size_t step = 0; step < fan.size(); ++step) {
      std::size_t found = fan.size();
      for (std::size_t k = 0; k < fan.size(); ++k) {
        if (fan[k].first != at) continue;
        if (found != fan.size()) return false;  // two triangles start at one neighbour
        found = k;
      }
      if (found == fan.size()) return false;  // an open fan: a border
      at = fan[found].second;
      if (at == fan[0].first && step + 1 < fan.size()) return false;  // closed before all were met
    }
    if (at != fan[0].first) return false;
    std::sort(weights.begin(), weights.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
    // Each neighbour twice (once from each triangle of their edge), summed.
    std::size_t out = 0;
    for (std::size_t k = 0; k < weights.size(); k += 2) {
      if (weights[k + 1].first != weights[k].first) return false;
      const Real w = weights[k].second + weights[k + 1].second;
      if (w != 0.0) weights[out++] = {weights[k].first, w};
    }
    weights.resize(out);
    if (weights.empty() || weights.size() > kBendStencilSize - 1) return false;
    const Real scale = 1.0 / (2.0 * std::sqrt(area[i]));
    for (auto& [p, w] : weights) w *= scale;
    return true;
  };
  constexpr Real kOpposite = -0.99;  // cos 172 degrees
  std::vector<BendStencil> stencils;
  std::vector<bool> taken;  // of the particle's links, those on a line already
  for (std::size_t i = 0; i < n; ++i) {
    if (!(area[i] > 0.0)) continue;
    const Vec3 x = rest.restPosition(i);
    BendStencil stencil{};
    stencil.v.fill(static_cast<ParticleIndex>(i));
    stencil.k.fill(0.0f);
    Real coefficient[kBendStencilSize] = {};
    int used = 1;
    if (cotangentStencil(i)) {
      for (const auto& [p, w] : weights) {
        stencil.v[used] = p;
        coefficient[used++] = w;
      }
    } else {
      // Its lines: at most two.
      int lines = 0;
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
    }
    // Rounded to single precision, the neighbours first (an entry whose weight rounds to 0 left
    // out, so the used ones come first and a 0 ends them), and k[0] what makes them sum to exactly 0.
    float sum = 0.0f;
    int kept = 1;
    for (int j = 1; j < used; ++j) {
      const auto k = static_cast<RestReal>(coefficient[j]);
      if (k == 0.0f) continue;
      stencil.v[kept] = stencil.v[j];
      stencil.k[kept++] = k;
      sum += k;
    }
    for (int j = kept; j < kBendStencilSize; ++j) stencil.v[j] = static_cast<ParticleIndex>(i);
    if (kept == 1) continue;
    stencil.k[0] = -sum;
    stencils.push_back(stencil);
  }
  return stencils;
}

}  // namespace drape::sim
