#include "drape/sim/collider.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace drape::sim {

Collider::Collider(ColliderSettings settings) : settings_(std::move(settings)) {
  if (settings_.shape == ColliderShape::plane) settings_.normal = glm::normalize(settings_.normal);
  settings_.orientation = glm::normalize(settings_.orientation);  // conjugate must be the inverse
  setTime(0.0);
  setTime(0.0);
  if (settings_.shape == ColliderShape::mesh) buildGrid();
}

bool Collider::moving() const {
  return glm::length(settings_.velocity) > 0.0 || glm::length(settings_.angularVelocity) > 0.0;
}

void Collider::setTime(Real t) {
  previousCentre_ = centre_;
  previousOrientation_ = orientation_;
  centre_ = settings_.position + settings_.velocity * t;
  const Real spin = glm::length(settings_.angularVelocity);
  orientation_ = spin > 0.0 ? glm::angleAxis(spin * t, settings_.angularVelocity / spin) * settings_.orientation
                            : settings_.orientation;
}

Vec3 Collider::carried(Vec3 p) const {
  return centre_ + orientation_ * (glm::conjugate(previousOrientation_) * (p - previousCentre_));
}

Vec3 Collider::surfaceVelocity(Vec3 p) const {
  return settings_.velocity + glm::cross(settings_.angularVelocity, p - centre_);
}

SurfaceDistance Collider::distance(Vec3 p, Real reach) const {
  const Vec3 inFrame = glm::conjugate(orientation_) * (p - centre_);
  SurfaceDistance d = local(inFrame, reach);
  d.normal = orientation_ * d.normal;
  return d;
}

Vec3 closestPointOnTriangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const Real d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const Real d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const Real denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

namespace {

Vec3 unitOr(Vec3 v, Vec3 fallback) {
  const Real length = glm::length(v);
  return length > 1e-12 ? v / length : fallback;
}

}  // namespace

SurfaceDistance Collider::local(Vec3 p, Real reach) const {
  const ColliderSettings& s = settings_;
  switch (s.shape) {
    case ColliderShape::plane: return {glm::dot(s.normal, p), s.normal};
    case ColliderShape::sphere: return {glm::length(p) - s.radius, unitOr(p, Vec3{0.0, 1.0, 0.0})};
    case ColliderShape::capsule: {
      const Real axisLength2 = glm::dot(s.halfAxis, s.halfAxis);
      const Real t = axisLength2 > 0.0 ? std::clamp(glm::dot(p, s.halfAxis) / axisLength2, -1.0, 1.0) : 0.0;
      const Vec3 away = p - s.halfAxis * t;
      return {glm::length(away) - s.radius, unitOr(away, Vec3{0.0, 1.0, 0.0})};
    }
    case ColliderShape::box: {
      // Rounded, it is the box shrunk by the radius and grown by it again: a distance and normal
      // from the inner box, less the radius. (Sharp: the radius is 0, and each figure is as it was.)
      const Vec3 q = glm::abs(p) - (s.halfExtents - s.rounding);
      const Vec3 outside = glm::max(q, Vec3{0.0});
      const Real outsideLength = glm::length(outside);
      if (outsideLength > 0.0) return {outsideLength - s.rounding, glm::sign(p) * outside / outsideLength};
      // Inside: the nearest face is along the axis with the largest (least negative) q.
      int axis = 0;
      if (q.y > q[axis]) axis = 1;
      if (q.z > q[axis]) axis = 2;
      Vec3 normal{0.0};
      normal[axis] = p[axis] >= 0.0 ? 1.0 : -1.0;
      return {q[axis] - s.rounding, normal};
    }
    case ColliderShape::mesh: {
      SurfaceDistance best{reach, Vec3{0.0, 1.0, 0.0}};
      if (gridCells_.x == 0) return best;
      if (!std::isfinite(p.x + p.y + p.z) ||
          glm::any(glm::greaterThan(
              glm::abs(p - glm::clamp(p, gridOrigin_, gridOrigin_ + Vec3(gridCells_) * cellSize_)), Vec3{reach}))) {
        return best;  // the whole mesh is out of reach (tested before any conversion to int)
      }
      // Cells clamped to the grid before they become ints: a reach of a huge motion (a particle
      // flung 1e15 m) puts p - reach far beyond what an int holds, and a NaN goes to cell 0.
      const auto cellOf = [&](Vec3 q) {
        const Vec3 f = glm::floor((q - gridOrigin_) / cellSize_);
        glm::ivec3 cell{0};
        for (int axis = 0; axis < 3; ++axis) {
          const double last = static_cast<double>(gridCells_[axis] - 1);
          cell[axis] = f[axis] >= 0.0 ? static_cast<int>(std::min(f[axis], last)) : 0;
        }
        return cell;
      };
      const glm::ivec3 lower = cellOf(p - reach), upper = cellOf(p + reach);
      const TriangleMesh& mesh = *s.mesh;
      for (int z = lower.z; z <= upper.z; ++z) {
        for (int y = lower.y; y <= upper.y; ++y) {
          for (int x = lower.x; x <= upper.x; ++x) {
            const int cell = (z * gridCells_.y + y) * gridCells_.x + x;
            for (std::uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
              const glm::uvec3& t = mesh.triangles[cellTriangles_[k]];
              const Vec3 closest =
                  closestPointOnTriangle(p, mesh.vertices[t.x], mesh.vertices[t.y], mesh.vertices[t.z]);
              const Real d = glm::length(p - closest);
              if (d < best.distance) {
                const Vec3 faceNormal =
                    glm::cross(mesh.vertices[t.y] - mesh.vertices[t.x], mesh.vertices[t.z] - mesh.vertices[t.x]);
                // A shell has two sides: the normal points to the side p is on.
                best = {d, unitOr(p - closest, unitOr(faceNormal, Vec3{0.0, 1.0, 0.0}))};
              }
            }
          }
        }
      }
      return best;
    }
  }
  return {std::numeric_limits<Real>::max(), Vec3{0.0, 1.0, 0.0}};
}

void Collider::buildGrid() {
  const TriangleMesh& mesh = *settings_.mesh;
  if (mesh.triangles.empty()) return;
  Vec3 lower{std::numeric_limits<Real>::max()}, upper{std::numeric_limits<Real>::lowest()};
  Real edges = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      lower = glm::min(lower, mesh.vertices[t[k]]);
      upper = glm::max(upper, mesh.vertices[t[k]]);
      edges += glm::length(mesh.vertices[t[(k + 1) % 3]] - mesh.vertices[t[k]]);
    }
  }
  // Cells about two average edges wide, at most 128 along any axis.
  const Vec3 size = upper - lower;
  cellSize_ = std::max({2.0 * edges / (3.0 * static_cast<Real>(mesh.triangles.size())),
                        std::max({size.x, size.y, size.z}) / 128.0, 1e-6});
  // A triangle is listed in every cell its bounding box touches. A few large triangles among many
  // small ones (small cells) would be listed millions of times each, so the cells grow until
  // the lists hold at most this many entries in all.
  const std::uint64_t budget = 16 * static_cast<std::uint64_t>(mesh.triangles.size()) + (std::uint64_t{1} << 22);
  const auto cellRange = [&](const glm::uvec3& t) {
    const Vec3 a = mesh.vertices[t.x], b = mesh.vertices[t.y], c = mesh.vertices[t.z];
    return std::pair{glm::ivec3(glm::floor((glm::min(a, glm::min(b, c)) - gridOrigin_) / cellSize_)),
                     glm::ivec3(glm::floor((glm::max(a, glm::max(b, c)) - gridOrigin_) / cellSize_))};
  };
  std::uint64_t entries = 0;
  while (true) {
    gridOrigin_ = lower - cellSize_ * 0.5;
    gridCells_ = glm::ivec3(glm::floor((size + cellSize_) / cellSize_)) + 1;
    entries = 0;
    for (const glm::uvec3& t : mesh.triangles) {
      const auto [from, to] = cellRange(t);
      const glm::ivec3 span = to - from + 1;
      entries +=
          static_cast<std::uint64_t>(span.x) * static_cast<std::uint64_t>(span.y) * static_cast<std::uint64_t>(span.z);
      if (entries > budget) break;
    }
    if (entries <= budget) break;
    cellSize_ *= 2.0;
  }
  const std::size_t cellCount = static_cast<std::size_t>(gridCells_.x) * gridCells_.y * gridCells_.z;
  const auto forEachCell = [&](const glm::uvec3& t, auto&& visit) {
    const auto [from, to] = cellRange(t);
    for (int z = from.z; z <= to.z; ++z) {
      for (int y = from.y; y <= to.y; ++y) {
        for (int x = from.x; x <= to.x; ++x) visit(static_cast<std::size_t>((z * gridCells_.y + y) * gridCells_.x + x));
      }
    }
  };
  // Counted first, then filled: two flat arrays, not a list per cell.
  cellStart_.assign(cellCount + 1, 0);
  for (const glm::uvec3& t : mesh.triangles) forEachCell(t, [&](std::size_t cell) { ++cellStart_[cell + 1]; });
  for (std::size_t i = 0; i < cellCount; ++i) cellStart_[i + 1] += cellStart_[i];
  cellTriangles_.assign(entries, 0);
  std::vector<std::uint32_t> filled(cellStart_.begin(), cellStart_.end() - 1);
  for (std::uint32_t i = 0; i < mesh.triangles.size(); ++i) {
    forEachCell(mesh.triangles[i], [&](std::size_t cell) { cellTriangles_[filled[cell]++] = i; });
  }
}

}  // namespace drape::sim
