#include "collider_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace drape::render {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Frame {
  sim::Vec3 centre;
  glm::dquat orientation;
  glm::vec3 point(sim::Vec3 local) const { return glm::vec3(centre + orientation * local); }
  glm::vec3 direction(sim::Vec3 local) const { return glm::vec3(glm::normalize(orientation * local)); }
};

void addVertex(ColliderGeometry& out, glm::vec3 position, glm::vec3 normal) {
  out.positions.push_back(position);
  out.normals.push_back(normal);
}

// Two unit vectors perpendicular to `axis` and to each other.
void basis(sim::Vec3 axis, sim::Vec3& u, sim::Vec3& v) {
  const sim::Vec3 helper = std::abs(axis.y) < 0.9 ? sim::Vec3{0, 1, 0} : sim::Vec3{1, 0, 0};
  u = glm::normalize(glm::cross(axis, helper));
  v = glm::cross(axis, u);
}

// A sphere of `radius` whose upper half (along `axis`) is shifted by +shift and lower half by
// -shift: a sphere when shift is 0, a capsule otherwise.
void sweptSphere(const Frame& frame, sim::Vec3 axis, sim::Vec3 shift, double radius, ColliderGeometry& out) {
  constexpr int kSegments = 32, kRings = 16;  // rings per hemisphere: kRings / 2
  sim::Vec3 u, v;
  basis(axis, u, v);
  const auto base = static_cast<std::uint32_t>(out.positions.size());
  int rows = 0;
  for (int ring = 0; ring <= kRings; ++ring) {
    for (int copy = 0; copy < (ring == kRings / 2 ? 2 : 1); ++copy) {  // the equator twice: the cylinder
      const double theta = kPi * ring / kRings;
      const sim::Vec3 offset = (ring < kRings / 2 || (ring == kRings / 2 && copy == 0)) ? shift : -shift;
      for (int segment = 0; segment <= kSegments; ++segment) {
        const double phi = 2.0 * kPi * segment / kSegments;
        const sim::Vec3 n = axis * std::cos(theta) + (u * std::cos(phi) + v * std::sin(phi)) * std::sin(theta);
        addVertex(out, frame.point(n * radius + offset), frame.direction(n));
      }
      ++rows;
    }
  }
  for (int row = 0; row + 1 < rows; ++row) {
    for (int segment = 0; segment < kSegments; ++segment) {
      const std::uint32_t a = base + static_cast<std::uint32_t>(row * (kSegments + 1) + segment);
      const std::uint32_t b = a + kSegments + 1;
      out.indices.insert(out.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  }
}

void quad(const Frame& frame, sim::Vec3 centre, sim::Vec3 normal, sim::Vec3 u, sim::Vec3 v, ColliderGeometry& out) {
  const auto base = static_cast<std::uint32_t>(out.positions.size());
  for (const auto& [a, b] : {std::pair{-1.0, -1.0}, std::pair{1.0, -1.0}, std::pair{1.0, 1.0}, std::pair{-1.0, 1.0}}) {
    addVertex(out, frame.point(centre + u * a + v * b), frame.direction(normal));
  }
  out.indices.insert(out.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

// A box of half extents h with its edges and corners rounded to radius r (0 < r <= min h): each
// face of the box h is a grid, flat where the inner box h - r is and, towards its sides, at the
// angles k / kRound of 45 degrees round the edge; each grid point p is carried to the inner box's
// nearest point plus r along the way from it to p, and faces that way.
void roundedBox(const Frame& frame, sim::Vec3 h, double r, ColliderGeometry& out) {
  constexpr int kRound = 4;
  const sim::Vec3 inner = h - sim::Vec3{r};
  std::array<std::vector<double>, 3> at;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double>& t = at[static_cast<std::size_t>(axis)];
    // (The last at the face's side itself, h: tan(45 degrees) is a rounding short of 1, and the
    // faces meeting there would miss each other by it.)
    const auto round = [&](int k) {
      return k == kRound ? h[axis] : inner[axis] + r * std::tan(0.25 * kPi * k / kRound);
    };
    for (int k = kRound; k >= 1; --k) t.push_back(-round(k));
    t.push_back(-inner[axis]);
    if (inner[axis] > 0.0) t.push_back(inner[axis]);
    for (int k = 1; k <= kRound; ++k) t.push_back(round(k));
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const std::vector<double>&ta = at[static_cast<std::size_t>(a)], &tb = at[static_cast<std::size_t>(b)];
    for (double side : {-1.0, 1.0}) {
      const auto base = static_cast<std::uint32_t>(out.positions.size());
      for (const double vb : tb) {
        for (const double va : ta) {
          sim::Vec3 p{0.0};
          p[axis] = side * h[axis];
          p[a] = va;
          p[b] = vb;
          const sim::Vec3 nearest = glm::clamp(p, -inner, inner);
          // Out of the face by r exactly (h - (h - r) may round to 0 for a radius far under h).
          sim::Vec3 away = p - nearest;
          away[axis] = side * r;
          const sim::Vec3 n = glm::normalize(away);
          addVertex(out, frame.point(nearest + n * r), frame.direction(n));
        }
      }
      const auto columns = static_cast<std::uint32_t>(ta.size());
      for (std::uint32_t j = 0; j + 1 < tb.size(); ++j) {
        for (std::uint32_t i = 0; i + 1 < columns; ++i) {
          const std::uint32_t c = base + j * columns + i;
          out.indices.insert(out.indices.end(), {c, c + 1, c + columns + 1, c, c + columns + 1, c + columns});
        }
      }
    }
  }
}

}  // namespace

bool showsAsTable(const sim::Collider& collider) {
  const sim::ColliderSettings& s = collider.settings();
  if (s.shape != sim::ColliderShape::plane) return false;
  const sim::Vec3 worldNormal = collider.orientation() * glm::normalize(s.normal);
  // A plane through the origin within ~8 degrees of level.
  return worldNormal.y > 0.99 && std::abs(collider.centre().y) < 1e-6;
}

void appendColliderGeometry(const sim::Collider& collider, ColliderGeometry& out, double inset) {
  const sim::ColliderSettings& s = collider.settings();
  const Frame frame{collider.centre(), collider.orientation()};
  inset = std::isfinite(inset) ? std::max(inset, 0.0) : 0.0;
  switch (s.shape) {
    case sim::ColliderShape::plane: {
      if (showsAsTable(collider)) return;
      const sim::Vec3 n = glm::normalize(s.normal);
      sim::Vec3 u, v;
      basis(n, u, v);
      quad(frame, -n * inset, n, u * 1.5, v * 1.5, out);
      return;
    }
    case sim::ColliderShape::sphere:
      sweptSphere(frame, {0, 1, 0}, sim::Vec3{0.0}, std::max(s.radius - inset, 0.5 * s.radius), out);
      return;
    case sim::ColliderShape::capsule: {
      const double length = glm::length(s.halfAxis);
      const sim::Vec3 axis = length > 0.0 ? s.halfAxis / length : sim::Vec3{1, 0, 0};
      sweptSphere(frame, axis, s.halfAxis, std::max(s.radius - inset, 0.5 * s.radius), out);
      return;
    }
    case sim::ColliderShape::box: {
      const sim::Vec3 h = glm::max(s.halfExtents - sim::Vec3{inset}, 0.5 * s.halfExtents);
      // Drawn `inset` inside: a rounded box's surface moved in by the inset is the box's half
      // extents and its radius each less the inset (sharp where the radius is less than it).
      const double r = std::min({std::max(s.rounding - inset, 0.0), h.x, h.y, h.z});
      // (A radius far under the box's size draws as sharp: there is nothing to see of it.)
      if (r > 1e-9 * std::max({h.x, h.y, h.z})) {
        roundedBox(frame, h, r, out);
        return;
      }
      for (int axis = 0; axis < 3; ++axis) {
        for (double side : {-1.0, 1.0}) {
          sim::Vec3 n{0.0}, u{0.0}, v{0.0};
          n[axis] = side;
          u[(axis + 1) % 3] = h[(axis + 1) % 3];
          v[(axis + 2) % 3] = h[(axis + 2) % 3];
          quad(frame, n * h[axis], n, u, v, out);
        }
      }
      return;
    }
    case sim::ColliderShape::mesh: {
      const sim::TriangleMesh& mesh = *s.mesh;
      for (const glm::uvec3& t : mesh.triangles) {
        const sim::Vec3 a = mesh.vertices[t.x], b = mesh.vertices[t.y], c = mesh.vertices[t.z];
        const sim::Vec3 n = glm::cross(b - a, c - a);
        if (!(glm::length(n) > 0.0)) continue;
        const auto base = static_cast<std::uint32_t>(out.positions.size());
        for (const sim::Vec3& p : {a, b, c}) addVertex(out, frame.point(p), frame.direction(n));
        out.indices.insert(out.indices.end(), {base, base + 1, base + 2});
      }
      return;
    }
  }
}

}  // namespace drape::render
