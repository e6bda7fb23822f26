// The exact count of intersecting triangle pairs (engine/sim/src/collision/intersections.cpp).
#include <gtest/gtest.h>

#include <cmath>

#include "drape/sim/intersections.hpp"
#include "drape/sim/world.hpp"
#include "world_builder.hpp"

namespace drape::sim {
namespace {

std::size_t pairs(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& triangles) {
  return countIntersections(positions, triangles).pairs;
}

// Two triangles, the second's corners 3, 4, 5 unless it shares some of the first's.
std::size_t pairsOfTwo(std::vector<Vec3> positions, glm::uvec3 second = {3, 4, 5}) {
  return pairs(positions, {{0, 1, 2}, second});
}

TEST(Intersections, TwoTrianglesCountAsTheyMeet) {
  const Vec3 a{-1, -1, 0}, b{1, -1, 0}, c{0, 1, 0};  // in z = 0
  // Through each other's interiors.
  EXPECT_EQ(pairsOfTwo({a, b, c, {0.1, -0.5, -1}, {0.1, -0.5, 1}, {0.1, 0.5, 0.2}}), 1u);
  // The same, moved past the first's edge: apart.
  EXPECT_EQ(pairsOfTwo({a, b, c, {2.1, -0.5, -1}, {2.1, -0.5, 1}, {2.1, 0.5, 0.2}}), 0u);
  // Above it, not reaching down.
  EXPECT_EQ(pairsOfTwo({a, b, c, {0.1, -0.5, 0.001}, {0.1, -0.5, 1}, {0.1, 0.5, 0.2}}), 0u);
  // A corner resting exactly on the other's face: closed triangles meet.
  EXPECT_EQ(pairsOfTwo({a, b, c, {0.1, -0.5, 0}, {0.1, -0.5, 1}, {0.1, 0.5, 0.2}}), 1u);
  // In one plane: overlapping, one inside the other, side by side.
  EXPECT_EQ(pairsOfTwo({a, b, c, {0.5, 0, 0}, {2, 0, 0}, {2, 1, 0}}), 1u);
  EXPECT_EQ(pairsOfTwo({a, b, c, {-0.1, -0.5, 0}, {0.1, -0.5, 0}, {0, 0, 0}}), 1u);
  EXPECT_EQ(pairsOfTwo({a, b, c, {1.5, -1, 0}, {3, -1, 0}, {2, 1, 0}}), 0u);
}

TEST(Intersections, NeighboursCountOnlyWhenOnePassesThroughTheOther) {
  const Vec3 v{0, 0, 0}, a{1, 0, 0}, b{0, 1, 0};
  // Across an edge: side by side, or folded up to almost flat, they only share the edge.
  EXPECT_EQ(pairs({v, a, b, {0.5, -0.5, 0}}, {{0, 1, 2}, {0, 1, 3}}), 0u);
  EXPECT_EQ(pairs({v, a, b, {0.5, 0.5, 1e-6}}, {{0, 1, 2}, {0, 1, 3}}), 0u);
  // Folded flat onto each other (a triangle turned over on a table), they overlap.
  EXPECT_EQ(pairs({v, a, b, {0.5, 0.5, 0}}, {{0, 1, 2}, {0, 1, 3}}), 1u);
  EXPECT_EQ(pairs({v, a, b, {-0.2, 0.1, 0}}, {{0, 1, 2}, {1, 2, 3}}), 1u);
  // At one corner: side by side in a plane, or folded up, they only touch there.
  EXPECT_EQ(pairs({v, a, b, {-1, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 3, 4}}), 0u);
  EXPECT_EQ(pairs({v, a, b, {-1, 0, 0}, {0, 0, 1}}, {{0, 1, 2}, {0, 3, 4}}), 0u);
  // At one corner, the other's far edge through the first: a fold through a vertex.
  EXPECT_EQ(pairs({v, a, b, {0.3, 0.3, -1}, {0.3, 0.3, 1}}, {{0, 1, 2}, {0, 3, 4}}), 1u);
}

TEST(Intersections, TwoCrossingQuadsMeetInAKnownNumberOfPairs) {
  // A: the unit square in z = 0, split along y = x. B: a square in the plane x = 0.3, y in
  // [0.1, 0.6], z in [-0.5, 0.5], split from (y, z) = (0.1, -0.5) to (0.6, 0.5). They cross on
  // x = 0.3, z = 0, y in [0.1, 0.6], which A's diagonal cuts at y = 0.3 and B's at y = 0.35: pieces
  // [0.1, 0.3] [0.3, 0.6] of A and [0.1, 0.35] [0.35, 0.6] of B, of which three pairs overlap.
  const std::vector<Vec3> x = {{0, 0, 0},        {1, 0, 0},        {1, 1, 0},       {0, 1, 0},
                               {0.3, 0.1, -0.5}, {0.3, 0.6, -0.5}, {0.3, 0.6, 0.5}, {0.3, 0.1, 0.5}};
  EXPECT_EQ(pairs(x, {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}}), 3u);
}

TEST(Intersections, AFlatSheetHasNoneAndTwoCrossingSheetsAsManyAsEveryPairTestedAlone) {
  WorldSettings settings = test::hangingSheet(16, 1, 1);
  World flat(settings);
  EXPECT_EQ(countIntersections(flat).pairs, 0u);
  EXPECT_EQ(countIntersections(flat).skipped, 0u);
  // A second sheet standing through the first, at an angle and off the lattice lines.
  ClothSettings standing = settings.cloths[0];
  standing.lattice = {17, 13, 0.8, 0.6, Vec3{-0.41, 1.83, -0.137}, LatticePlane::xy};
  standing.pins.clear();
  settings.cloths.push_back(standing);
  World crossing(settings);
  const IntersectionCount counted = countIntersections(crossing);
  // The same pairs, one by one, without the broad phase.
  std::vector<Vec3> positions;
  std::vector<glm::uvec3> triangles;
  for (const Cloth& cloth : crossing.cloths()) {
    const auto base = static_cast<unsigned>(positions.size());
    positions.insert(positions.end(), cloth.state.position.begin(), cloth.state.position.end());
    for (const glm::uvec3& t : cloth.rest.triangles) triangles.push_back(t + base);
  }
  std::size_t oneByOne = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (std::size_t j = i + 1; j < triangles.size(); ++j) oneByOne += pairs(positions, {triangles[i], triangles[j]});
  }
  EXPECT_GT(counted.pairs, 40u);  // the line of crossing runs 0.8 m across cells 5 and 7 cm wide
  EXPECT_EQ(counted.pairs, oneByOne);
}

TEST(Intersections, ATriangleFarOutOrNotFiniteIsSkippedAndSaidSo) {
  const double nan = std::nan("");
  const IntersectionCount c = countIntersections({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {nan, 0, 0}, {2e4, 0, 0}},
                                                 {{0, 1, 2}, {0, 3, 1}, {0, 4, 2}});
  EXPECT_EQ(c.pairs, 0u);
  EXPECT_EQ(c.skipped, 2u);
}

}  // namespace
}  // namespace drape::sim
