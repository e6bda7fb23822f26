#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/mesh/outline.hpp"
#include "drape/sim/cloth.hpp"
#include "drape/sim/settings.hpp"

namespace drape::sim {
namespace {

using mesh::OutlineSpec;
using Points = std::vector<glm::dvec2>;

// A drawn cloth's rest mesh as the engine makes it: the outline meshed (drape_mesh), then
// constrained by lattice position (constrainMesh).
struct OutlineCloth {
  ClothRest rest;
  Points loop;
  bool tookLargestLoop = false;
};

OutlineCloth buildFromOutline(const OutlineSpec& spec, ConstraintSelection selection = {}) {
  mesh::OutlineMesh shape = mesh::meshOutline(spec);
  OutlineCloth cloth;
  cloth.rest = constrainMesh(
      {std::move(shape.positions), std::move(shape.triangles), std::move(shape.nodes), spec.spacing}, selection);
  cloth.loop = std::move(shape.loop);
  cloth.tookLargestLoop = shape.tookLargestLoop;
  return cloth;
}

// cross(b - a, c - a).y for points (x, 0, z) given as (x, z): positive is counter-clockwise seen from +y.
double turn(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) { return (b.y - a.y) * (c.x - a.x) - (b.x - a.x) * (c.y - a.y); }

double signedArea(const Points& loop) {
  double sum = 0.0;
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) sum += turn(loop[0], loop[i], loop[i + 1]);
  return 0.5 * sum;
}

double perimeter(const Points& loop) {
  double sum = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) sum += glm::length(loop[(i + 1) % loop.size()] - loop[i]);
  return sum;
}

glm::dvec2 flat(const Vec3& p) { return {p.x, p.z}; }

double distanceToSegment(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}

double distanceToLoop(glm::dvec2 p, const Points& loop) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < loop.size(); ++i)
    best = std::min(best, distanceToSegment(p, loop[i], loop[(i + 1) % loop.size()]));
  return best;
}

// Proper crossing or touching of two closed segments (for the loop's simplicity).
bool segmentsMeet(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
  const double o1 = turn(a, b, c), o2 = turn(a, b, d), o3 = turn(c, d, a), o4 = turn(c, d, b);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0) || (o3 > 0 && o4 > 0) || (o3 < 0 && o4 < 0)) return false;
  if (o1 != 0 || o2 != 0 || o3 != 0 || o4 != 0) return true;
  return std::max(std::min(a.x, b.x), std::min(c.x, d.x)) <= std::min(std::max(a.x, b.x), std::max(c.x, d.x)) &&
         std::max(std::min(a.y, b.y), std::min(c.y, d.y)) <= std::min(std::max(a.y, b.y), std::max(c.y, d.y));
}

bool isSimpleLoop(const Points& loop) {
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      if (segmentsMeet(loop[i], loop[i + 1], loop[j], loop[(j + 1) % n])) return false;
    }
  }
  return true;
}

// Do the open interiors of two counter-clockwise triangles overlap by more than `slack`? Separating axes: the
// triangles are apart if some edge of either has the whole other triangle on its outer side.
bool interiorsOverlap(const std::array<glm::dvec2, 3>& a, const std::array<glm::dvec2, 3>& b, double slack) {
  for (const auto* t : {&a, &b}) {
    const auto& other = t == &a ? b : a;
    for (int e = 0; e < 3; ++e) {
      const glm::dvec2 p = (*t)[e], q = (*t)[(e + 1) % 3];
      const double lengthPQ = glm::length(q - p);
      bool separated = true;
      for (const glm::dvec2& r : other) {
        if (turn(p, q, r) / lengthPQ > slack) separated = false;
      }
      if (separated) return false;
    }
  }
  return true;
}

// How far a rest position may be from where the mesher put it, in the plane: the rest positions are
// single-precision offsets from the first particle, each coordinate within half a float ulp of the
// largest offset (2^-24 of it), so a point within sqrt(2) times that, less than 2^-23 of it.
double restRounding(const ClothRest& rest) {
  double extent = 0.0;
  for (const glm::vec3& offset : rest.restOffsets) {
    extent = std::max({extent, std::abs(static_cast<double>(offset.x)), std::abs(static_cast<double>(offset.z))});
  }
  return extent * std::numeric_limits<float>::epsilon();
}

struct MeshReport {
  double area = 0.0;
  double minQuality = 1.0;
  double minEdge = std::numeric_limits<double>::infinity();
  std::size_t boundaryEdges = 0;
};

// Every property the builder promises, checked from the outside.
MeshReport checkMesh(const OutlineCloth& cloth, const OutlineSpec& spec) {
  MeshReport report;
  const ClothRest& rest = cloth.rest;
  const Points& loop = cloth.loop;
  EXPECT_EQ(rest.columns, 0);
  EXPECT_EQ(rest.rows, 0);
  EXPECT_GE(loop.size(), 3u);
  EXPECT_GT(signedArea(loop), 0.0) << "loop must be counter-clockwise seen from +y";
  if (loop.size() < 400) {
    EXPECT_TRUE(isSimpleLoop(loop));
  }
  EXPECT_FALSE(rest.triangles.empty());

  std::vector<char> used(rest.particleCount(), 0);
  std::map<std::pair<ParticleIndex, ParticleIndex>, int> directed;
  for (const glm::uvec3& t : rest.triangles) {
    const std::array<ParticleIndex, 3> v{t.x, t.y, t.z};
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(v[c], rest.particleCount());
      used[v[c]] = 1;
      ++directed[{v[c], v[(c + 1) % 3]}];
    }
    const glm::dvec2 a = flat(rest.restPosition(t.x)), b = flat(rest.restPosition(t.y)),
                     c = flat(rest.restPosition(t.z));
    const Vec3 normal =
        glm::cross(rest.restPosition(t.y) - rest.restPosition(t.x), rest.restPosition(t.z) - rest.restPosition(t.x));
    EXPECT_GT(normal.y, 0.0) << "triangle must face +y";
    report.area += 0.5 * turn(a, b, c);
    const double squares = glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c);
    report.minQuality = std::min(report.minQuality, 2.0 * std::sqrt(3.0) * turn(a, b, c) / squares);
  }
  for (std::size_t p = 0; p < rest.particleCount(); ++p) {
    EXPECT_TRUE(used[p]) << "particle " << p << " belongs to no triangle";
    EXPECT_EQ(rest.restPosition(p).y, spec.height);
  }
  // Each directed edge once (consistent winding); an edge without its twin is on the boundary, and must lie on the
  // loop: both ends and the middle within 1e-9 of it, and the rest positions' rounding.
  const double rounding = restRounding(rest);
  double boundaryLength = 0.0;
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge used twice in the same direction: triangles overlap";
    const glm::dvec2 a = flat(rest.restPosition(edge.first)), b = flat(rest.restPosition(edge.second));
    report.minEdge = std::min(report.minEdge, glm::length(b - a));
    if (directed.count({edge.second, edge.first}) != 0) continue;
    ++report.boundaryEdges;
    boundaryLength += glm::length(b - a);
    EXPECT_LT(distanceToLoop(a, loop), 1e-9 + rounding);
    EXPECT_LT(distanceToLoop(b, loop), 1e-9 + rounding);
    EXPECT_LT(distanceToLoop(0.5 * (a + b), loop), 1e-9 + rounding) << "boundary edge leaves the loop";
  }
  // The boundary runs once around the loop, and the triangles cover it exactly.
  EXPECT_NEAR(boundaryLength, perimeter(loop),
              1e-9 * std::max(1.0, perimeter(loop)) + 2.0 * rounding * static_cast<double>(report.boundaryEdges));
  // Rounding moves the boundary by at most `rounding`: the area by at most that times the perimeter.
  EXPECT_NEAR(report.area, signedArea(loop), 1e-9 * std::max(1.0, signedArea(loop)) + rounding * perimeter(loop));
  // Every corner of the loop is a particle.
  for (const glm::dvec2& corner : loop) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < rest.particleCount(); ++p) {
      nearest = std::min(nearest, glm::length(flat(rest.restPosition(p)) - corner));
    }
    EXPECT_LT(nearest, 1e-9 + rounding);
  }
  // No two triangles overlap (beyond rounding), checked directly on nearby pairs.
  if (rest.triangles.size() < 20000) {
    const double cell = spec.spacing;
    std::map<std::pair<long long, long long>, std::vector<std::size_t>> buckets;
    std::vector<std::array<glm::dvec2, 3>> corners;
    for (const glm::uvec3& t : rest.triangles) {
      corners.push_back({flat(rest.restPosition(t.x)), flat(rest.restPosition(t.y)), flat(rest.restPosition(t.z))});
      const auto& c = corners.back();
      const glm::dvec2 low = glm::min(glm::min(c[0], c[1]), c[2]), high = glm::max(glm::max(c[0], c[1]), c[2]);
      for (auto x = static_cast<long long>(std::floor(low.x / cell));
           x <= static_cast<long long>(std::floor(high.x / cell)); ++x) {
        for (auto z = static_cast<long long>(std::floor(low.y / cell));
             z <= static_cast<long long>(std::floor(high.y / cell)); ++z) {
          buckets[{x, z}].push_back(corners.size() - 1);
        }
      }
    }
    std::set<std::pair<std::size_t, std::size_t>> overlapping;
    for (const auto& [key, list] : buckets) {
      for (std::size_t i = 0; i < list.size(); ++i) {
        for (std::size_t j = i + 1; j < list.size(); ++j) {
          if (interiorsOverlap(corners[list[i]], corners[list[j]], 1e-9 * spec.spacing)) {
            overlapping.insert({list[i], list[j]});
          }
        }
      }
    }
    EXPECT_TRUE(overlapping.empty()) << overlapping.size() << " overlapping triangle pairs";
  }
  // Constraints: no pair twice (over all kinds), never a particle with itself, rest length the rest distance
  // (as a RestReal).
  std::set<std::pair<ParticleIndex, ParticleIndex>> pairs;
  for (const ConstraintKind kind : kConstraintKinds) {
    for (const DistanceConstraint& c : rest.of(kind)) {
      EXPECT_NE(c.a, c.b);
      EXPECT_TRUE(pairs.insert({std::min(c.a, c.b), std::max(c.a, c.b)}).second) << "duplicate " << name(kind);
      EXPECT_GT(c.restLength, 0.0);
      EXPECT_EQ(c.restLength, static_cast<RestReal>(glm::length(rest.restPosition(c.b) - rest.restPosition(c.a))));
    }
  }
  // Every triangle edge is held by a stretch or shear constraint.
  for (const auto& [edge, count] : directed) {
    EXPECT_TRUE(pairs.count({std::min(edge.first, edge.second), std::max(edge.first, edge.second)}) == 1)
        << "triangle edge without a constraint";
  }
  return report;
}

Points square(double side, glm::dvec2 origin = {0.0, 0.0}) {
  return {origin, origin + glm::dvec2(side, 0.0), origin + glm::dvec2(side, side), origin + glm::dvec2(0.0, side)};
}

Points circle(double radius, int count, glm::dvec2 centre = {0.0, 0.0}) {
  Points points;
  for (int i = 0; i < count; ++i) {
    const double a = 2.0 * std::numbers::pi * i / count;
    points.push_back(centre + radius * glm::dvec2(std::cos(a), std::sin(a)));
  }
  return points;
}

Points star(int arms, double outer, double inner) {
  Points points;
  for (int i = 0; i < 2 * arms; ++i) {
    const double a = std::numbers::pi * i / arms;
    points.push_back((i % 2 == 0 ? outer : inner) * glm::dvec2(std::cos(a), std::sin(a)));
  }
  return points;
}

std::string messageOf(const OutlineSpec& spec) {
  try {
    buildFromOutline(spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(Outline, SquareIsTheLattice) {
  // A 1 m square at 0.1 m spacing is the 11 x 11 lattice: same particles, triangles and constraints.
  const OutlineSpec spec{square(1.0), 0.1, 0.25};
  const OutlineCloth cloth = buildFromOutline(spec);
  const MeshReport report = checkMesh(cloth, spec);
  EXPECT_FALSE(cloth.tookLargestLoop);
  EXPECT_NEAR(report.area, 1.0, 1e-9);
  const ClothRest lattice = buildLattice({11, 11, 1.0, 1.0, Vec3{0.0, 0.25, 0.0}, LatticePlane::xz});
  EXPECT_EQ(cloth.rest.particleCount(), lattice.particleCount());
  EXPECT_EQ(cloth.rest.triangles.size(), lattice.triangles.size());
  for (const ConstraintKind kind : kConstraintKinds) {
    EXPECT_EQ(cloth.rest.of(kind).size(), lattice.of(kind).size()) << name(kind);
  }
  // Every particle sits on a lattice point (to the 1/1024-spacing grid the loop is held on).
  for (std::size_t i = 0; i < cloth.rest.particleCount(); ++i) {
    const Vec3 p = cloth.rest.restPosition(i);
    EXPECT_NEAR(p.x * 10.0, std::round(p.x * 10.0), 1e-2);
    EXPECT_NEAR(p.z * 10.0, std::round(p.z * 10.0), 1e-2);
  }
}

TEST(Outline, SquareOffTheLatticeStillCoversItExactly) {
  for (const double side : {0.53, 0.77, 1.0}) {
    const OutlineSpec spec{square(side, {0.013, -0.021}), 0.05, 0.0};
    const OutlineCloth cloth = buildFromOutline(spec);
    const MeshReport report = checkMesh(cloth, spec);
    // The loop is the square held on a 1/4096-spacing grid: each corner moves by at most 2 sqrt(2) / 4096 spacings.
    EXPECT_NEAR(report.area, side * side, 4.0 * side * 2.0 * std::sqrt(2.0) / 4096.0 * spec.spacing);
    // The border rule: every inside node, plus about one particle per spacing of border.
    const double cells = side / spec.spacing;
    EXPECT_GE(static_cast<double>(cloth.rest.particleCount()), cells * cells);
    EXPECT_LE(static_cast<double>(cloth.rest.particleCount()), (cells + 3.0) * (cells + 3.0));
  }
}

TEST(Outline, CircleAreaApproachesPiRSquared) {
  const double radius = 0.5;
  for (const double spacing : {0.1, 0.05, 0.02}) {
    const OutlineSpec spec{circle(radius, 720), spacing, 0.0};
    const OutlineCloth cloth = buildFromOutline(spec);
    const MeshReport report = checkMesh(cloth, spec);
    const double disc = std::numbers::pi * radius * radius;
    // The triangles cover the loop exactly. The loop is the circle simplified to within spacing / 4 (its corners
    // on the circle), so it misses at most perimeter * spacing / 4 of the disc: spacing / (2 r) of it (10%, 5% and
    // 2% here; measured 2.6%, 2.6% and 0.6%).
    EXPECT_NEAR(report.area, signedArea(cloth.loop), 1e-9 + restRounding(cloth.rest) * perimeter(cloth.loop));
    EXPECT_LT(disc - report.area, disc * spacing / (2.0 * radius)) << "spacing " << spacing;
    EXPECT_LE(report.area, disc * (1.0 + 1e-4));
    // No slivers along the curved border (the lattice's half cell is 0.87), no particles crowding each other.
    EXPECT_GT(report.minQuality, 0.2) << "spacing " << spacing;
    EXPECT_GT(report.minEdge, 0.25 * spacing) << "spacing " << spacing;
  }
}

TEST(Outline, LShapeAndStarWork) {
  const Points lShape{{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.4}, {0.4, 0.4}, {0.4, 1.0}, {0.0, 1.0}};
  for (const Points& points : {lShape, star(5, 0.5, 0.2), star(7, 0.6, 0.35)}) {
    const OutlineSpec spec{points, 0.05, 0.1};
    const OutlineCloth cloth = buildFromOutline(spec);
    const MeshReport report = checkMesh(cloth, spec);
    EXPECT_NEAR(report.area, std::abs(signedArea(points)), 1e-3);
    EXPECT_FALSE(cloth.tookLargestLoop);
    EXPECT_GT(report.minQuality, 0.2);
    EXPECT_GT(report.minEdge, 0.25 * spec.spacing);
  }
}

TEST(Outline, ClockwiseStrokeGivesTheSameCloth) {
  Points points = star(5, 0.5, 0.2);
  const OutlineCloth forward = buildFromOutline({points, 0.05, 0.0});
  std::reverse(points.begin(), points.end());
  const OutlineCloth backward = buildFromOutline({points, 0.05, 0.0});
  EXPECT_NEAR(signedArea(forward.loop), signedArea(backward.loop), 1e-9);
  EXPECT_GT(signedArea(backward.loop), 0.0);
  EXPECT_EQ(forward.rest.particleCount(), backward.rest.particleCount());
}

TEST(Outline, FigureEightKeepsTheLargerLobe) {
  // Two circles drawn as one stroke crossing at the origin: radius 0.5 on the right, 0.25 on the left.
  Points points;
  for (int i = 0; i < 200; ++i) {
    const double a = std::numbers::pi - 2.0 * std::numbers::pi * i / 200.0;
    points.push_back(glm::dvec2(0.5, 0.0) + 0.5 * glm::dvec2(std::cos(a), std::sin(a)));
  }
  for (int i = 0; i < 100; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 100.0;
    points.push_back(glm::dvec2(-0.25, 0.0) + 0.25 * glm::dvec2(std::cos(a), std::sin(a)));
  }
  const OutlineSpec spec{points, 0.05, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  checkMesh(cloth, spec);
  EXPECT_TRUE(cloth.tookLargestLoop);
  EXPECT_NEAR(signedArea(cloth.loop), std::numbers::pi * 0.25, 0.05);
  for (const glm::dvec2& p : cloth.loop) EXPECT_GT(p.x, -1e-3);
}

TEST(Outline, OvershootingTheStartKeepsTheCircle) {
  Points points = circle(0.4, 100);
  for (int i = 0; i < 10; ++i) points.push_back(points[static_cast<std::size_t>(i)] + glm::dvec2(0.0, 0.02));
  const OutlineSpec spec{points, 0.05, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  checkMesh(cloth, spec);
  EXPECT_NEAR(signedArea(cloth.loop), std::numbers::pi * 0.16, 0.03);
}

TEST(Outline, DuplicatesAndJitterAreHarmless) {
  Points repeated;
  for (const glm::dvec2& p : square(0.6)) {
    for (int k = 0; k < 5; ++k) repeated.push_back(p);
  }
  const OutlineSpec clean{repeated, 0.05, 0.0};
  const OutlineCloth fromRepeated = buildFromOutline(clean);
  checkMesh(fromRepeated, clean);
  EXPECT_EQ(fromRepeated.rest.particleCount(), buildFromOutline({square(0.6), 0.05, 0.0}).rest.particleCount());

  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  Points shaky;
  for (const glm::dvec2& p : circle(0.45, 3000)) shaky.push_back(p + glm::dvec2(jitter(random), jitter(random)));
  const OutlineSpec spec{shaky, 0.05, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  checkMesh(cloth, spec);
  EXPECT_NEAR(signedArea(cloth.loop), std::numbers::pi * 0.45 * 0.45, 0.05);
}

TEST(Outline, ConstraintsFollowTheLatticeInside) {
  const OutlineSpec spec{circle(0.5, 360), 0.05, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  checkMesh(cloth, spec);
  // Deep inside, stretch is the spacing, shear its diagonal and bend twice the spacing.
  std::size_t lattice = 0;
  for (const ConstraintKind kind : kConstraintKinds) {
    const double expected = kind == ConstraintKind::stretch ? 0.05
                            : kind == ConstraintKind::shear ? 0.05 * std::sqrt(2.0)
                                                            : 0.1;
    for (const DistanceConstraint& c : cloth.rest.of(kind)) {
      const glm::dvec2 middle = 0.5 * (flat(cloth.rest.restPosition(c.a)) + flat(cloth.rest.restPosition(c.b)));
      if (glm::length(middle) > 0.35) continue;
      // A float (within 6e-8 of itself), between rest positions each within the rounding of theirs.
      EXPECT_NEAR(c.restLength, expected, 1e-8 + 2.0 * restRounding(cloth.rest)) << name(kind);
      ++lattice;
    }
  }
  EXPECT_GT(lattice, 500u);
  // Unused kinds are not generated.
  const OutlineCloth stretchOnly = buildFromOutline(spec, {true, false, false});
  EXPECT_FALSE(stretchOnly.rest.of(ConstraintKind::stretch).empty());
  EXPECT_TRUE(stretchOnly.rest.of(ConstraintKind::shear).empty());
  EXPECT_TRUE(stretchOnly.rest.of(ConstraintKind::bend).empty());
}

TEST(Outline, IsDeterministic) {
  const OutlineSpec spec{star(6, 0.5, 0.3), 0.03, 0.0};
  const OutlineCloth a = buildFromOutline(spec), b = buildFromOutline(spec);
  EXPECT_EQ(a.rest.restOrigin, b.rest.restOrigin);
  EXPECT_EQ(a.rest.restOffsets, b.rest.restOffsets);
  EXPECT_EQ(a.rest.triangles, b.rest.triangles);
  EXPECT_EQ(a.loop, b.loop);
}

TEST(Outline, BadOutlinesSayWhy) {
  const auto expectMessage = [](const OutlineSpec& spec, const std::string& part) {
    const std::string message = messageOf(spec);
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  expectMessage({{{0, 0}, {1, 0}}, 0.05, 0.0}, "fewer than 3 distinct points");
  expectMessage({{{0, 0}, {1, 0}, {0, 0}, {1, 0}, {1, 0}}, 0.05, 0.0}, "fewer than 3 distinct points");
  expectMessage({{}, 0.05, 0.0}, "fewer than 3 distinct points");
  expectMessage({{{0, 0}, {1, 1}, {2, 2}, {0.5, 0.5}}, 0.05, 0.0}, "no area");
  expectMessage({{{0, 0}, {1, 0}, {2, 0}, {0.5, 0}}, 0.05, 0.0}, "no area");
  expectMessage({square(1.0), 0.0, 0.0}, "spacing must be at least 1e-09 m");
  expectMessage({square(1.0), -0.1, 0.0}, "spacing must be at least 1e-09 m");
  expectMessage({square(1.0), nan, 0.0}, "spacing must be at least 1e-09 m");
  expectMessage({square(1.0), inf, 0.0}, "spacing must be at least 1e-09 m");
  // So fine that a metre in the loop's grid units was infinite, cast to an integer (fuzz_outline's
  // crashers: a subnormal and a normal double).
  expectMessage({{{0.0, 0.0}, {1e-317, 0.0}, {0.0, 1e-317}}, 3.2e-319, 0.0}, "spacing must be at least 1e-09 m");
  expectMessage({{{0.0, 0.0}, {1e-305, 0.0}, {0.0, 1e-305}}, 4.1e-307, 0.0}, "spacing must be at least 1e-09 m");
  expectMessage({square(1.0), 0.05, nan}, "height must be finite");
  expectMessage({{{0, 0}, {1, nan}, {1, 1}, {0, 1}}, 0.05, 0.0}, "non-finite point");
  expectMessage({{{0, 0}, {inf, 0}, {1, 1}, {0, 1}}, 0.05, 0.0}, "non-finite point");
  expectMessage({square(0.04), 0.05, 0.0}, "less than one cell");
  expectMessage({square(0.01), 0.05, 0.0}, "less than one cell");
  // 10 m x 10 m at 5 mm: about 2001^2 = 4 million particles.
  const std::string tooMany = messageOf({square(10.0), 0.005, 0.0});
  EXPECT_NE(tooMany.find("particles, more than the limit of " + std::to_string(mesh::kMaxParticles)), std::string::npos)
      << tooMany;
  EXPECT_NE(tooMany.find("about 4004001 particles"), std::string::npos) << tooMany;
  expectMessage({square(1e300), 0.05, 0.0}, "spacings");
  expectMessage({{{-1e308, -1e308}, {1e308, -1e308}, {0, 1e308}}, 0.05, 0.0}, "spacings");
}

TEST(Outline, NeverCrashesOnHostileInput) {
  // Huge and tiny coordinates, huge point counts, scribbles: a cloth or a std::invalid_argument, quickly.
  const auto survives = [](const OutlineSpec& spec) {
    try {
      const OutlineCloth cloth = buildFromOutline(spec);
      EXPECT_FALSE(cloth.rest.triangles.empty());
    } catch (const std::invalid_argument&) {
    }
  };
  survives({square(1.0, {1e9, -1e9}), 0.05, 0.0});
  survives({{{1e300, 1e300}, {1e300 + 1e285, 1e300}, {1e300, 1e300 + 1e285}}, 1e284, 0.0});
  survives({square(1e-300), 1e-301, 0.0});
  survives({square(1.0), 1e-300, 0.0});
  survives({square(1.0), 1e300, 0.0});
  std::mt19937 random(3);
  std::uniform_real_distribution<double> anywhere(0.0, 1.0);
  Points scribble;
  for (int i = 0; i < 100000; ++i) scribble.push_back({anywhere(random), anywhere(random)});
  survives({scribble, 0.05, 0.0});
  survives({scribble, 0.004, 0.0});
  // A zigzag far finer than the spacing: 200000 teeth 2 mm apart at 1 cm. Too intricate, and said so quickly.
  Points zigzag;
  for (int i = 0; i < 200000; ++i) zigzag.push_back({i * 0.002, (i % 2) * 0.5});
  zigzag.push_back({400.0, -0.1});
  zigzag.push_back({0.0, -0.1});
  EXPECT_NE(messageOf({zigzag, 0.01, 0.0}).find("too intricate"), std::string::npos);
}

TEST(Outline, AMillionPointsAreFine) {
  const OutlineSpec spec{circle(0.5, 1'000'000), 0.05, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  checkMesh(cloth, spec);
}

// A square metre at 1 cm spacing: about ten thousand particles, every invariant held. (How long it
// takes is measured, not asserted: about 15 ms in Release on this machine.)
TEST(Outline, SquareMetreAtOneCentimetre) {
  const OutlineSpec spec{circle(std::sqrt(1.0 / std::numbers::pi), 400), 0.01, 0.0};
  const OutlineCloth cloth = buildFromOutline(spec);
  EXPECT_GT(cloth.rest.particleCount(), 9000u);
  checkMesh(cloth, spec);
}

// Random star-shaped and random-walk outlines at random spacings: every invariant, every time.
TEST(Outline, RandomOutlinesKeepEveryPromise) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    Points points;
    const int count = 3 + static_cast<int>(unit(random) * 40);
    for (int i = 0; i < count; ++i) {
      const double a = 2.0 * std::numbers::pi * (i + 0.8 * unit(random)) / count;
      const double r = 0.1 + 0.5 * unit(random);
      points.push_back(glm::dvec2(0.3 * unit(random), 0.0) + r * glm::dvec2(std::cos(a), std::sin(a)));
    }
    const OutlineSpec spec{points, 0.02 + 0.08 * unit(random), 0.0};
    try {
      const OutlineCloth cloth = buildFromOutline(spec);
      checkMesh(cloth, spec);
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find("internal"), std::string::npos) << message;
    }
    if (HasFailure()) {
      ADD_FAILURE() << "trial " << trial;
      return;
    }
  }
}

}  // namespace
}  // namespace drape::sim
