#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/cloth.hpp"
#include "drape/sim/world.hpp"
#include "solver/pair_order.hpp"

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

// The seed's lattice, constraint by constraint in the order the seed's sweep takes them
// (Gauss-Seidel: the order is part of the result), written out as the seed walks it: per particle,
// row by row, its neighbour along the row, then down the column; per cell, its diagonal from
// (column, row), then the other; per particle, two along the row, then two down. meshConstraints
// lists them so, and the sweep takes them so (by particle pair, SolverScratch::sweepOrder) from the
// lists the cloth keeps in an order of its own.
TEST(Lattice, ConstraintsComeInTheSeedsOrderInEitherPlane) {
  for (const LatticePlane plane : {LatticePlane::xz, LatticePlane::xy}) {
    const int columns = 5, rows = 4;
    const ClothRest rest = buildLattice({columns, rows, 1.0, 0.75, Vec3{0.0}, plane});
    std::array<std::vector<std::pair<ParticleIndex, ParticleIndex>>, kConstraintKindCount> expected;
    const auto at = [&](int column, int row) { return static_cast<ParticleIndex>(row * columns + column); };
    for (int row = 0; row < rows; ++row) {
      for (int column = 0; column < columns; ++column) {
        if (column + 1 < columns) expected[0].push_back({at(column, row), at(column + 1, row)});
        if (row + 1 < rows) expected[0].push_back({at(column, row), at(column, row + 1)});
        if (column + 1 < columns && row + 1 < rows) {
          expected[1].push_back({at(column, row), at(column + 1, row + 1)});
          expected[1].push_back({at(column + 1, row), at(column, row + 1)});
        }
        if (column + 2 < columns) expected[2].push_back({at(column, row), at(column + 2, row)});
        if (row + 2 < rows) expected[2].push_back({at(column, row), at(column, row + 2)});
      }
    }
    // meshConstraints lists them so.
    std::vector<glm::ivec2> nodes;
    for (int row = 0; row < rows; ++row) {
      for (int column = 0; column < columns; ++column) nodes.push_back({column, row});
    }
    const auto listed = meshConstraints(rest, rest.triangles, nodes);
    for (const ConstraintKind kind : kConstraintKinds) {
      std::vector<std::pair<ParticleIndex, ParticleIndex>> made;
      for (const DistanceConstraint& c : listed[static_cast<std::size_t>(kind)]) made.push_back({c.a, c.b});
      EXPECT_EQ(made, expected[static_cast<std::size_t>(kind)]) << name(kind) << " in " << name(plane);
    }
    // The lattice keeps the same constraints in the engine's one order (orderConstraints): the
    // stretch links the rows' line by line, then the columns', each along its line; shear and bend
    // in batches no two of whose constraints share a particle.
    std::vector<std::pair<ParticleIndex, ParticleIndex>> lines;
    for (int row = 0; row < rows; ++row) {
      for (int column = 0; column + 1 < columns; ++column) lines.push_back({at(column, row), at(column + 1, row)});
    }
    for (int column = 0; column < columns; ++column) {
      for (int row = 0; row + 1 < rows; ++row) lines.push_back({at(column, row), at(column, row + 1)});
    }
    for (const ConstraintKind kind : kConstraintKinds) {
      std::vector<std::pair<ParticleIndex, ParticleIndex>> swept;
      for (const std::uint32_t k : byParticlePair(rest.of(kind))) {
        const DistanceConstraint& c = rest.of(kind)[k];
        swept.push_back({std::min(c.a, c.b), std::max(c.a, c.b)});
      }
      EXPECT_EQ(swept, expected[static_cast<std::size_t>(kind)]) << name(kind) << " swept in " << name(plane);
    }
    for (const ConstraintKind kind : kConstraintKinds) {
      std::vector<std::pair<ParticleIndex, ParticleIndex>> kept;
      for (const DistanceConstraint& c : rest.of(kind)) kept.push_back({c.a, c.b});
      if (kind == ConstraintKind::stretch) {
        EXPECT_EQ(kept, lines) << name(plane);
        continue;
      }
      std::vector<std::pair<ParticleIndex, ParticleIndex>> sorted = kept;
      std::sort(sorted.begin(), sorted.end());
      EXPECT_EQ(sorted, expected[static_cast<std::size_t>(kind)]) << name(kind) << " in " << name(plane);
      // Batches: a run with no particle twice, and the next constraint shares one with the run.
      std::vector<int> seen(rest.particleCount(), 0);
      int batches = 1;
      for (const auto& [a, b] : kept) {
        if (seen[a] || seen[b]) {
          ++batches;
          std::fill(seen.begin(), seen.end(), 0);
        }
        seen[a] = seen[b] = 1;
      }
      EXPECT_LE(batches, 6) << name(kind) << " in " << name(plane);
    }
  }
}

// constrainMesh's rules where a mesh is not a whole lattice: a cell with one triangle gets only the
// diagonal that triangle has; a particle off the lattice is joined by stretch along its edges; a
// bend needs both stretch edges through its middle.
TEST(ConstrainMesh, APartCellGetsOnlyItsOwnDiagonalAndAnOffLatticeCornerStretch) {
  // Particles 0-4 stand for nodes (0,0) (1,0) (0,1) (1,1) (2,0); 5 stands for none. The cell (0,0)
  // is whole (two triangles split along (1,0)-(0,1)); the cell (1,0) has one triangle, (1,0) (1,1)
  // (2,0), whose diagonal is (1,1)-(2,0); a last triangle reaches particle 5.
  LatticeMesh mesh;
  mesh.spacing = 1.0;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 0, 1}, {2, 0, 0}, {2.5, 0, 0.5}};
  mesh.nodes = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0}, kNoNode};
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {1, 3, 4}, {4, 3, 5}};
  const ClothRest rest = constrainMesh(mesh);
  // In lattice order as meshConstraints lists them (constrainMesh keeps the same in the engine's
  // order).
  const auto listed = meshConstraints(rest, rest.triangles, mesh.nodes);
  const auto pairs = [&](ConstraintKind kind) {
    std::vector<std::pair<ParticleIndex, ParticleIndex>> made, kept;
    for (const DistanceConstraint& c : listed[static_cast<std::size_t>(kind)]) made.push_back({c.a, c.b});
    for (const DistanceConstraint& c : rest.of(kind)) kept.push_back({std::min(c.a, c.b), std::max(c.a, c.b)});
    std::vector<std::pair<ParticleIndex, ParticleIndex>> sorted = made;
    for (auto& [a, b] : sorted) std::tie(a, b) = std::pair{std::min(a, b), std::max(a, b)};
    std::sort(sorted.begin(), sorted.end());
    std::sort(kept.begin(), kept.end());
    EXPECT_EQ(kept, sorted) << name(kind);
    return made;
  };
  using Pairs = std::vector<std::pair<ParticleIndex, ParticleIndex>>;
  // Every triangle edge but the diagonals, by particle pair; (3, 5) and (4, 5) reach the particle off the lattice.
  EXPECT_EQ(pairs(ConstraintKind::stretch), (Pairs{{0, 1}, {0, 2}, {1, 3}, {1, 4}, {2, 3}, {3, 5}, {4, 5}}));
  // Cell (0,0): its own diagonal (1,2) and, being whole, (0,3) first; cell (1,0): only (4,3), its triangle's.
  EXPECT_EQ(pairs(ConstraintKind::shear), (Pairs{{0, 3}, {1, 2}, {4, 3}}));
  // (0,0)-(2,0) through (1,0): both stretch edges there. Nothing down a column (no third row).
  EXPECT_EQ(pairs(ConstraintKind::bend), (Pairs{{0, 4}}));
  // Rest lengths from the positions.
  for (const ConstraintKind kind : kConstraintKinds) {
    for (const DistanceConstraint& c : rest.of(kind)) {
      EXPECT_FLOAT_EQ(c.restLength, static_cast<float>(glm::length(mesh.positions[c.b] - mesh.positions[c.a])));
    }
  }
}

TEST(ConstrainMesh, RefusesWhatIsNotAMesh) {
  LatticeMesh mesh;
  mesh.spacing = 1.0;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  mesh.nodes = {{0, 0}, {1, 0}, {0, 1}};
  mesh.triangles = {{0, 2, 1}};
  EXPECT_NO_THROW(constrainMesh(mesh));
  LatticeMesh bad = mesh;
  bad.nodes.pop_back();
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);  // a node (or none) per particle
  bad = mesh;
  bad.nodes[2] = {1, 0};
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);  // one node stood for twice
  bad = mesh;
  bad.nodes[2] = {-3, 0};
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);  // off the lattice's quarter
  bad = mesh;
  bad.triangles[0] = {0, 2, 3};
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);  // a corner out of range
  bad = mesh;
  bad.triangles[0] = {0, 2, 2};
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);  // a corner twice
  bad = mesh;
  bad.positions[1].x = std::nan("");
  EXPECT_THROW(constrainMesh(bad), std::invalid_argument);
}

TEST(Lattice, RestLengthsAreTheSpacing) {
  // 5 columns over 1 m: 0.25 m along x; 4 rows over 0.6 m: 0.2 m along z.
  const ClothRest rest = buildLattice({5, 4, 1.0, 0.6, Vec3{0.0}, LatticePlane::xz});
  const auto alongX = [&](const DistanceConstraint& c) { return rest.restPosition(c.a).z == rest.restPosition(c.b).z; };
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
  // Rounded up where asked: never below the length, and the next float at most above it.
  EXPECT_EQ(toRestLengthAtLeast(0.25), 0.25f);
  for (const Real length : {0.1, 1.0 / 3.0, 0.7, 123.456}) {
    const RestReal up = toRestLengthAtLeast(length);
    EXPECT_GE(static_cast<Real>(up), length);
    EXPECT_LT(static_cast<Real>(std::nextafter(up, 0.0f)), length);
  }
  for (const Real bad : {-1.0, 1e39, 1e-50, std::numeric_limits<Real>::infinity(), std::nan("")}) {
    EXPECT_THROW(toRestLength(bad), std::invalid_argument) << bad;
  }
  // A lattice too large or too fine for them is refused, not built with infinite or zero lengths (too
  // fine, its particles' single-precision rest positions would coincide).
  EXPECT_THROW(buildLattice({3, 3, 1e39, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
  EXPECT_THROW(buildLattice({3, 3, 1e-100, 1.0, Vec3{0.0}, LatticePlane::xz}), std::invalid_argument);
}

TEST(Lattice, MassesSinglePrecisionCannotHoldAreRefused) {
  EXPECT_EQ(toMass(0.25), 0.25f);
  EXPECT_EQ(toMass(0.1), 0.1f);  // rounded as a float rounds
  for (const Real bad : {0.0, -1.0, 1e39, 1e-40, 1e-50, std::numeric_limits<Real>::infinity(), std::nan("")}) {
    EXPECT_THROW(toMass(bad), std::invalid_argument) << bad;  // (1e-40: subnormal)
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
  EXPECT_EQ(flat.restPosition(flat.index(2, 1)), (Vec3{3.0, 2.0, 4.0}));
  const ClothRest hanging = buildLattice({3, 2, 2.0, 1.0, origin, LatticePlane::xy});
  EXPECT_EQ(hanging.restPosition(hanging.index(2, 1)), (Vec3{3.0, 1.0, 3.0}));
  // Front faces: +y for a flat sheet, +z for a hanging one.
  for (const auto& [rest, up] : {std::pair{&flat, Vec3{0, 1, 0}}, std::pair{&hanging, Vec3{0, 0, 1}}}) {
    for (const glm::uvec3& t : rest->triangles) {
      const Vec3 n = glm::cross(rest->restPosition(t.y) - rest->restPosition(t.x),
                                rest->restPosition(t.z) - rest->restPosition(t.x));
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

TEST(RestPositions, AreHeldToTheClothsSizeWhereverItIs) {
  // 101 columns over 1 m, 3 km from the world's origin. Offsets from the first particle are within
  // 2^-24 m of the lattice (floats of at most 1 m); positions themselves in single precision would
  // be up to 1.2e-4 m off, rest lengths up to 2 % of the spacing.
  const Vec3 far{3000.1, -2000.2, 1000.3};
  const Real dx = 1.0 / 100.0;
  const ClothRest rest = buildLattice({101, 3, 1.0, 0.02, far, LatticePlane::xz});
  EXPECT_EQ(rest.restOrigin, far);
  EXPECT_EQ(rest.restPosition(0), far);
  for (int column = 0; column < 101; ++column) {
    const Vec3 expected = far + Vec3{dx * column, 0.0, 0.0};
    EXPECT_LE(glm::length(rest.restPosition(rest.index(column, 0)) - expected), std::ldexp(1.0, -24)) << column;
  }
  for (const DistanceConstraint& c : rest.of(ConstraintKind::stretch)) {
    // The rest length is measured between the rounded positions: the spacing within two roundings.
    EXPECT_NEAR(c.restLength, dx, 2.0 * std::ldexp(1.0, -24) + 1e-9);
    EXPECT_EQ(c.restLength, toRestLength(glm::length(rest.restPosition(c.b) - rest.restPosition(c.a))));
  }
}

TEST(RestPositions, SetAgainFromTheirOwnDoublesGiveBackTheSameOffsets) {
  // What a snapshot does: writes restPosition(i) as doubles and sets them again. The first
  // particle's offset is 0, so the origin comes back exactly, and with it every offset.
  for (const Vec3 origin : {Vec3{0.0}, Vec3{-7123.456789, 1.5, 4987.654321}, Vec3{1e-3, 2.0 / 3.0, -1e4 / 7.0}}) {
    ClothRest rest = buildLattice({64, 33, 1.7, 0.9, origin, LatticePlane::xy});
    rest.duplicateRestPosition(rest.index(40, 20));  // as tearing does
    EXPECT_EQ(rest.particleCount(), 64u * 33u + 1u);
    EXPECT_EQ(rest.restPosition(rest.particleCount() - 1), rest.restPosition(rest.index(40, 20)));
    std::vector<Vec3> written(rest.particleCount());
    for (std::size_t i = 0; i < written.size(); ++i) written[i] = rest.restPosition(i);
    ClothRest back;
    back.setRestPositions(written);
    EXPECT_EQ(back.restOrigin, rest.restOrigin);
    EXPECT_EQ(back.restOffsets, rest.restOffsets);
  }
}

TEST(RestPositions, OffsetsSinglePrecisionCannotHoldAreRefused) {
  ClothRest rest;
  rest.setRestPositions({});
  EXPECT_EQ(rest.particleCount(), 0u);
  const Real inf = std::numeric_limits<Real>::infinity();
  for (const Vec3 bad :
       {Vec3{1e39, 0.0, 0.0}, Vec3{0.0, -4e38, 0.0}, Vec3{0.0, 0.0, inf}, Vec3{std::nan(""), 0.0, 0.0}}) {
    EXPECT_THROW(rest.setRestPositions({Vec3{0.0}, bad}), std::invalid_argument)
        << bad.x << " " << bad.y << " " << bad.z;
  }
  EXPECT_THROW(rest.setRestPositions({Vec3{inf, 0.0, 0.0}}), std::invalid_argument);  // the origin too
  // Far out, but within float range of the first particle.
  rest.setRestPositions({Vec3{1e38, 0.0, 0.0}, Vec3{-1e38, 0.0, 0.0}});
  EXPECT_EQ(rest.restOffsets[1].x, static_cast<float>(-2e38));
}

}  // namespace
}  // namespace drape::sim
