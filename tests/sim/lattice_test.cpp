#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "drape/sim/cloth.hpp"
#include "drape/sim/world.hpp"

namespace drape::sim {
namespace {

TEST(Lattice, ConstraintCountsFollowTheSeedsLattice) {
  const ClothRest rest = buildLattice({5, 4, 1.0, 0.75, Vec3{0.0}, LatticePlane::xz});
  EXPECT_EQ(rest.particleCount(), 20u);
  EXPECT_EQ(rest.of(ConstraintKind::stretch).size(), 4u * 4 + 5u * 3);  // horizontal + vertical neighbours
  EXPECT_EQ(rest.of(ConstraintKind::shear).size(), 2u * 4 * 3);         // both diagonals of every cell
  EXPECT_EQ(rest.of(ConstraintKind::bend).size(), 3u * 4 + 5u * 2);     // neighbours two apart
  EXPECT_EQ(rest.triangles.size(), 2u * 4 * 3);
}

TEST(Lattice, RestLengthsAreTheSpacing) {
  // 5 columns over 1 m: 0.25 m along x; 4 rows over 0.6 m: 0.2 m along z.
  const ClothRest rest = buildLattice({5, 4, 1.0, 0.6, Vec3{0.0}, LatticePlane::xz});
  const auto alongX = [&](const DistanceConstraint& c) {
    return rest.restPositions[c.a].z == rest.restPositions[c.b].z;
  };
  // Rest lengths are single precision (RestReal): the nearest float, give or take an ulp or two.
  for (const DistanceConstraint& c : rest.of(ConstraintKind::stretch)) {
    EXPECT_FLOAT_EQ(c.restLength, alongX(c) ? 0.25f : 0.2f);
  }
  for (const DistanceConstraint& c : rest.of(ConstraintKind::shear))
    EXPECT_FLOAT_EQ(c.restLength, static_cast<float>(std::hypot(0.25, 0.2)));
  for (const DistanceConstraint& c : rest.of(ConstraintKind::bend))
    EXPECT_FLOAT_EQ(c.restLength, alongX(c) ? 0.5f : 0.4f);
}

TEST(Lattice, RestLengthsSinglePrecisionCannotHoldAreRefused) {
  EXPECT_EQ(toRestLength(0.0), 0.0f);
  EXPECT_EQ(toRestLength(0.25), 0.25f);
  for (const Real bad : {-1.0, 1e39, 1e-50, std::numeric_limits<Real>::infinity(), std::nan("")}) {
    EXPECT_THROW(toRestLength(bad), std::invalid_argument) << bad;
  }
  // A lattice too large or too fine for them is refused, not built with infinite or zero lengths.
  EXPECT_THROW(buildLattice({3, 3, 1e39, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
  EXPECT_THROW(buildLattice({3, 3, 1e-100, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
}

TEST(Lattice, MassesSinglePrecisionCannotHoldAreRefused) {
  EXPECT_EQ(toMass(0.25), 0.25f);
  EXPECT_EQ(toMass(0.1), 0.1f);  // rounded as a float rounds
  for (const Real bad : {0.0, -1.0, 1e39, 1e-50, std::numeric_limits<Real>::infinity(), std::nan("")}) {
    EXPECT_THROW(toMass(bad), std::invalid_argument) << bad;
  }
  // A world whose particles would weigh that is refused, not built with masses of 0.
  WorldSettings settings;
  settings.cloths.push_back({});
  settings.cloths[0].masses.push_back({0, 0, 1e-300});
  EXPECT_THROW(World{settings}, std::invalid_argument);
}

TEST(Lattice, IndexIsRowMajorAndPlanesPointTheRightWay) {
  const Vec3 origin{1.0, 2.0, 3.0};
  const ClothRest flat = buildLattice({3, 2, 2.0, 1.0, origin, LatticePlane::xz});
  EXPECT_EQ(flat.index(2, 1), 5u);
  EXPECT_EQ(flat.restPositions[flat.index(2, 1)], (Vec3{3.0, 2.0, 4.0}));
  const ClothRest hanging = buildLattice({3, 2, 2.0, 1.0, origin, LatticePlane::xy});
  EXPECT_EQ(hanging.restPositions[hanging.index(2, 1)], (Vec3{3.0, 1.0, 3.0}));
  // Front faces: +y for a flat sheet, +z for a hanging one.
  for (const auto& [rest, up] : {std::pair{&flat, Vec3{0, 1, 0}}, std::pair{&hanging, Vec3{0, 0, 1}}}) {
    for (const glm::uvec3& t : rest->triangles) {
      const Vec3 n = glm::cross(rest->restPositions[t.y] - rest->restPositions[t.x],
                                rest->restPositions[t.z] - rest->restPositions[t.x]);
      EXPECT_GT(glm::dot(n, up), 0.0);
    }
  }
}

TEST(Lattice, ChainHasNoShearAndNoTriangles) {
  const ClothRest chain = buildLattice({10, 1, 0.9, 1.0, Vec3{0.0}, LatticePlane::xy});
  EXPECT_EQ(chain.of(ConstraintKind::stretch).size(), 9u);
  EXPECT_EQ(chain.of(ConstraintKind::shear).size(), 0u);
  EXPECT_EQ(chain.of(ConstraintKind::bend).size(), 8u);
  EXPECT_TRUE(chain.triangles.empty());
  const ClothRest one = buildLattice({1, 1, 1.0, 1.0, Vec3{0.0}, LatticePlane::xz});
  EXPECT_EQ(one.particleCount(), 1u);
  for (const auto& list : one.constraints) EXPECT_TRUE(list.empty());
}

TEST(Lattice, UnusedKindsAreNotGenerated) {
  const ClothRest rest = buildLattice({4, 4, 1.0, 1.0, Vec3{0.0}, LatticePlane::xz}, {true, false, false});
  EXPECT_FALSE(rest.of(ConstraintKind::stretch).empty());
  EXPECT_TRUE(rest.of(ConstraintKind::shear).empty());
  EXPECT_TRUE(rest.of(ConstraintKind::bend).empty());
}

TEST(Lattice, RejectsImpossibleSpecs) {
  EXPECT_THROW(buildLattice({0, 4, 1.0, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
  EXPECT_THROW(buildLattice({4, 4, 0.0, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
  EXPECT_THROW(buildLattice({5000, 4, 1.0, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
  EXPECT_THROW(buildLattice({4000, 4000, 1.0, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
}

}  // namespace
}  // namespace drape::sim
