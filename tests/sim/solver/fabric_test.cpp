// A fabric in physical units: its bend stencils' energy against the plate's, and what a fabric
// cloth is made of.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "drape/mesh/outline.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"
#include "solver/bending.hpp"

namespace drape::sim {
namespace {

// sum over stencils of B / 2 |C|^2, C = sum_{j>0} k_j (x_j - x_0).
double bendingEnergy(const ClothRest& rest, const std::vector<Vec3>& x, double rigidity) {
  double energy = 0.0;
  for (const BendStencil& b : rest.bending) {
    Vec3 c{0.0};
    for (int j = 1; j < kBendStencilSize; ++j) c += double(b.k[j]) * (x[b.v[j]] - x[b.v[0]]);
    energy += 0.5 * rigidity * glm::dot(c, c);
  }
  return energy;
}

ClothRest flatRest(int n) {
  LatticeSpec spec;
  spec.columns = spec.rows = n;
  ClothRest rest = buildLattice(spec);
  rest.bending = buildBendStencils(rest);
  return rest;
}

// The sheet rolled onto a cylinder of radius r whose axis lies at `degrees` to the columns.
std::vector<Vec3> rolled(const ClothRest& rest, double r, double degrees) {
  const double t = degrees * std::numbers::pi / 180.0;
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < rest.particleCount(); ++i) {
    const Vec3 p = rest.restPosition(i) - Vec3{0.5, 0.0, 0.5};
    const double across = p.x * std::cos(t) + p.z * std::sin(t), along = -p.x * std::sin(t) + p.z * std::cos(t);
    x.push_back({r * std::sin(across / r), r * (1.0 - std::cos(across / r)), along});
  }
  return x;
}

TEST(BendStencils, EveryParticleButTheCornersHasOneAndAFlatSheetStoresNoEnergy) {
  const ClothRest rest = flatRest(9);
  // Every particle but the four corners (on no line: their two links are at right angles).
  ASSERT_EQ(rest.bending.size(), 81u - 4u);
  int sizes[kBendStencilSize + 1] = {};
  for (const BendStencil& b : rest.bending) ++sizes[stencilSize(b)];
  EXPECT_EQ(sizes[5], 49);  // inside: the cotangent Laplacian, on square cells the five-point one
  EXPECT_EQ(sizes[3], 28);  // the border: its own line only
  std::vector<Vec3> x;
  // Turned and moved far away, still flat: no energy (the coefficients sum to 0, exactly).
  const double c = std::cos(0.7), s = std::sin(0.7);
  for (std::size_t i = 0; i < rest.particleCount(); ++i) {
    const Vec3 p = rest.restPosition(i);
    x.push_back(Vec3{c * p.x - s * p.y, s * p.x + c * p.y, p.z} + Vec3{1000.0, -250.0, 3.0});
  }
  EXPECT_LT(bendingEnergy(rest, x, 1.0), 1e-9);
}

TEST(BendStencils, ARolledSheetStoresThePlatesEnergyWhicheverWayItIsRolled) {
  // A plate of rigidity B curved to radius R stores B / (2 R^2) per square metre. The border's
  // stencils see only the border's own line, so the two borders the roll bends across lose their
  // half cells: on a 1 m sheet of 41 columns 39/40 of it is kept.
  const ClothRest rest = flatRest(41);
  const double B = 2.0e-5, R = 0.5, plate = B / (2.0 * R * R);
  for (double degrees : {0.0, 90.0}) {
    EXPECT_NEAR(bendingEnergy(rest, rolled(rest, R, degrees), B) / plate, 39.0 / 40.0, 2e-3) << degrees;
  }
  // At any other angle as much, to within what the border loses (all four borders bend then), and
  // the same either way round.
  for (double degrees : {22.5, 45.0, 67.5}) {
    const double ratio = bendingEnergy(rest, rolled(rest, R, degrees), B) / plate;
    EXPECT_GT(ratio, 0.955) << degrees;
    EXPECT_LT(ratio, 0.976) << degrees;
    EXPECT_NEAR(bendingEnergy(rest, rolled(rest, R, -degrees), B) / plate, ratio, 1e-9) << degrees;
  }
  // Quadratic: half the radius, four times the energy.
  EXPECT_NEAR(bendingEnergy(rest, rolled(rest, R / 2, 0.0), B) / bendingEnergy(rest, rolled(rest, R, 0.0), B), 4.0,
              0.01);
  // A twist (y = t x z) bends no line: only stretching resists it.
  std::vector<Vec3> twisted;
  for (std::size_t i = 0; i < rest.particleCount(); ++i) {
    const Vec3 p = rest.restPosition(i);
    twisted.push_back({p.x, 0.5 * (p.x - 0.5) * (p.z - 0.5), p.z});
  }
  EXPECT_LT(bendingEnergy(rest, twisted, B), 1e-15);
}

// A drawn square (an outline, its fill's lattice at `degrees` to its sides), side 0.3 m at 1 cm.
ClothRest drawnSquare(double degrees) {
  const double t = degrees * std::numbers::pi / 180.0, side = 0.3;
  const glm::dvec2 u{std::cos(t), std::sin(t)}, v{-std::sin(t), std::cos(t)}, corner{0.0031, 0.0047};
  mesh::OutlineSpec outline;
  outline.spacing = 0.01;
  for (const glm::dvec2 p :
       {glm::dvec2{0.0, 0.0}, glm::dvec2{side, 0.0}, glm::dvec2{side, side}, glm::dvec2{0.0, side}})
    outline.points.push_back(corner + p.x * u + p.y * v);
  mesh::OutlineMesh shape = mesh::meshOutline(outline);
  ClothRest rest = constrainMesh(
      LatticeMesh{std::move(shape.positions), std::move(shape.triangles), std::move(shape.nodes), outline.spacing});
  rest.bending = buildBendStencils(rest);
  return rest;
}

TEST(BendStencils, ADrawnSheetRolledAcrossItsSidesStoresThePlatesEnergyAtAnyAngleToItsLattice) {
  // A drawn square whose fill's lattice lies at an angle to its sides, so they clip its cells,
  // rolled onto a cylinder about an axis along one side and then the other. Inside (where a
  // particle's triangles close round it) the stencils are the cotangent Laplacian, exact for any
  // cells: within 2 % of the plate's energy at any angle. The two lines through a particle that
  // stood there before (its most nearly opposite links, within 8 degrees) stored 2 to 27 % too
  // much where the cells are clipped. The border keeps its own line's curvature only, so the whole
  // sheet stores a little less than the plate (3 to 4 %), as the lattice's does.
  const double B = 2.0e-5, R = 0.2;
  for (double degrees : {0.0, 10.0, 22.5, 30.0, 45.0}) {
    const ClothRest rest = drawnSquare(degrees);
    const std::vector<Real> areas = particleAreas(rest);
    double area = 0.0;
    for (Real a : areas) area += a;
    for (double side : {0.0, 90.0}) {
      const double turn = (degrees + side) * std::numbers::pi / 180.0;
      std::vector<Vec3> x;
      for (std::size_t i = 0; i < rest.particleCount(); ++i) {
        const Vec3 p = rest.restPosition(i) - rest.restPosition(0);
        const double across = p.x * std::cos(turn) + p.z * std::sin(turn);
        const double along = -p.x * std::sin(turn) + p.z * std::cos(turn);
        x.push_back({R * std::sin(across / R), R * (1.0 - std::cos(across / R)), along});
      }
      double insideEnergy = 0.0, insideArea = 0.0;
      for (const BendStencil& b : rest.bending) {
        int used = 0;
        Vec3 c{0.0};
        for (int j = 1; j < kBendStencilSize; ++j) {
          c += double(b.k[j]) * (x[b.v[j]] - x[b.v[0]]);
          used += b.k[j] != 0.0f;
        }
        if (used <= 2) continue;  // a border's line (inside: the cotangent Laplacian, or two lines)
        insideEnergy += 0.5 * B * glm::dot(c, c);
        insideArea += areas[b.v[0]];
      }
      const double plate = B / (2.0 * R * R);
      ASSERT_GT(insideArea, 0.9 * area) << degrees;
      EXPECT_NEAR(insideEnergy / (plate * insideArea), 1.0, 0.02) << degrees << " degrees, side " << side;
      const double whole = bendingEnergy(rest, x, B) / (plate * area);
      EXPECT_GT(whole, 0.95) << degrees << " degrees, side " << side;
      EXPECT_LT(whole, 0.985) << degrees << " degrees, side " << side;
    }
  }
}

// Particle 0 and six particles round it on a circle, spokes and rim as stretch links. `once`: six
// triangles go once round it; `doubled`: and one of them listed twice; `pinched`: two fans of three
// triangles each (the even corners' and the odd ones'), each closed, meeting only at particle 0.
enum class Fan { once, doubled, pinched };
ClothRest hexagon(Fan fan) {
  ClothRest rest;
  std::vector<Vec3> x{Vec3{0.0}};
  for (int k = 0; k < 6; ++k)
    x.push_back({0.1 * std::cos(k * std::numbers::pi / 3.0), 0.0, 0.1 * std::sin(k * std::numbers::pi / 3.0)});
  rest.setRestPositions(x);
  auto& stretch = rest.constraints[static_cast<std::size_t>(ConstraintKind::stretch)];
  for (std::uint32_t k = 1; k <= 6; ++k) stretch.push_back({0u, k, 0.1f});
  if (fan == Fan::pinched) {
    for (std::uint32_t first : {1u, 2u}) {
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t a = first + 2 * k, b = first + 2 * ((k + 1) % 3);
        rest.triangles.push_back({0u, b, a});
        stretch.push_back({a, b, static_cast<float>(0.1 * std::sqrt(3.0))});
      }
    }
  } else {
    for (std::uint32_t k = 1; k <= 6; ++k) {
      rest.triangles.push_back({0u, k % 6 + 1, k});
      stretch.push_back({k, k % 6 + 1, 0.1f});
    }
    if (fan == Fan::doubled) rest.triangles.push_back(rest.triangles[2]);
  }
  rest.bending = buildBendStencils(rest);
  return rest;
}

TEST(BendStencils, AParticleWhoseTrianglesGoOnceRoundItTakesTheCotangentLaplacianAndOtherwiseItsLines) {
  for (const Fan fan : {Fan::once, Fan::doubled, Fan::pinched}) {
    SCOPED_TRACE(static_cast<int>(fan));
    const ClothRest rest = hexagon(fan);
    ASSERT_FALSE(rest.bending.empty());
    const BendStencil& centre = rest.bending[0];
    ASSERT_EQ(centre.v[0], 0u);
    // Once round: all six neighbours, each weighted (cot 60 + cot 60) / (2 sqrt(A)), A a third of
    // the six triangles'. A triangle listed twice, or two fans that each close (every neighbour
    // still on two triangles), have no one Laplacian: two of the three lines through it instead.
    const double area = 6.0 * (std::sqrt(3.0) / 4.0 * 0.01) / 3.0;
    EXPECT_EQ(stencilSize(centre), fan == Fan::once ? 7 : 5);
    if (fan == Fan::once) {
      for (int j = 1; j < 7; ++j) EXPECT_NEAR(centre.k[j], 2.0 / std::sqrt(3.0) / (2.0 * std::sqrt(area)), 1e-4);
    }
    // Flat, it stores nothing either way.
    std::vector<Vec3> x;
    for (std::size_t i = 0; i < rest.particleCount(); ++i) x.push_back(rest.restPosition(i));
    EXPECT_LT(bendingEnergy(rest, x, 1.0), 1e-12);
  }
}

// A world of one lying fabric lattice.
WorldSettings fabricSheet(int columns, int rows, Real width, Real height, Fabric fabric = {}) {
  WorldSettings settings;
  ClothSettings cloth;
  cloth.lattice = {columns, rows, width, height, Vec3{0.0}, LatticePlane::xz};
  cloth.fabric = fabric;
  settings.cloths.push_back(cloth);
  return settings;
}

TEST(Fabric, WeighsItsAreaAndBendsByStencilsInsteadOfTheSeedsLinks) {
  const World world(fabricSheet(5, 4, 0.4, 0.3, Fabric{0.25, 3e-5, 2e4, 100.0}));
  const Cloth& c = world.cloths()[0];
  double total = 0.0;
  for (MassReal m : c.state.mass) total += m;
  EXPECT_NEAR(total, 0.25 * 0.4 * 0.3, 1e-8);
  // A corner with one triangle of the cell's two weighs a third of that triangle's area, an inside
  // particle six times as much.
  EXPECT_NEAR(c.state.mass[c.rest.index(0, 0)] / c.state.mass[c.rest.index(2, 2)], 1.0 / 6.0, 1e-6);
  EXPECT_TRUE(c.rest.of(ConstraintKind::bend).empty());
  EXPECT_EQ(c.rest.bending.size(), 5u * 4u - 4u);  // all but the corners
  EXPECT_DOUBLE_EQ(c.settings.material(ConstraintKind::stretch).compliance, 1.0 / 2e4);
  EXPECT_DOUBLE_EQ(c.settings.material(ConstraintKind::shear).compliance, 1.0 / 100.0);
}

TEST(Fabric, IsRefusedWhereItCannotMeanAnything) {
  WorldSettings settings = fabricSheet(5, 1, 0.4, 0.0);
  EXPECT_THROW(World{settings}, std::invalid_argument);  // a chain has no area
  settings.cloths[0].lattice.rows = 3;
  settings.cloths[0].lattice.height = 0.2;
  settings.cloths[0].fabric->bendingRigidity = -1.0;
  EXPECT_THROW(World{settings}, std::invalid_argument);
  settings.cloths[0].fabric->bendingRigidity = 1e-5;
  settings.solver.model = Model::force;
  EXPECT_THROW(World{settings}, std::invalid_argument);
  settings.solver.model = Model::position;
  EXPECT_NO_THROW(World{settings});
}

TEST(FabricSubsteps, ASubstepNoLongerThanTheSpacingOverTheSpeed) {
  SolverSettings solver;  // 1/60 s, 1 substep, 7.5 m/s
  EXPECT_EQ(substepsFor(solver, 0.0125), 10);
  EXPECT_EQ(substepsFor(solver, 0.00625), 20);
  EXPECT_EQ(substepsFor(solver, 0.003125), 40);
  EXPECT_EQ(substepsFor(solver, 0.2), 1);  // a coarse cloth: what was asked
  solver.dt = 0.0166666667;                // 1/60 as scene files write it: still 10, not 11
  EXPECT_EQ(substepsFor(solver, 0.0125), 10);
  solver.substeps = 50;  // never fewer than asked
  EXPECT_EQ(substepsFor(solver, 0.0125), 50);
  solver.substeps = 1;
  EXPECT_EQ(substepsFor(solver, 1e-9), kMaxSubsteps);
  EXPECT_EQ(substepsFor(solver, 0.0), 1);  // no cloth with a fabric
  solver.fabricSubstepSpeed = 0.0;         // switched off
  EXPECT_EQ(substepsFor(solver, 0.003125), 1);
  solver.fabricSubstepSpeed = 7.5;
  solver.model = Model::force;  // no fabric there
  EXPECT_EQ(substepsFor(solver, 0.003125), 1);
}

TEST(FabricSubsteps, AWorldRunsWhatItsFinestFabricAsksAndKeepsItsVelocitiesAsThatChanges) {
  // A seed sheet at 1 cm falls on its own substep; a 2.5 mm fabric sheet added asks for 50 of a
  // 60 Hz step; taken away, the world goes back to 4. The falling sheet's velocity is the same on
  // either side of each change (its Verlet history rescaled to the new substep).
  WorldSettings settings = fabricSheet(11, 11, 0.1, 0.1);
  settings.cloths[0].fabric.reset();
  settings.solver.substeps = 4;
  World world(settings);
  EXPECT_EQ(world.substeps(), 4);
  world.run(10);
  const Vec3 before = world.velocity(0, 60);
  ASSERT_LT(before.y, -1.0);
  ClothSettings fine = fabricSheet(41, 41, 0.1, 0.1).cloths[0];
  fine.lattice.origin = Vec3{2.0, 0.0, 0.0};
  world.addCloth(fine);
  EXPECT_EQ(world.substeps(), 50);
  EXPECT_NEAR(glm::length(world.velocity(0, 60) - before), 0.0, 1e-9);
  EXPECT_NEAR(world.substepDt(), 1.0 / 60.0 / 50.0, 1e-15);
  world.run(1);
  const Vec3 during = world.velocity(0, 60);
  EXPECT_NEAR(during.y - before.y, -9.81 / 60.0, 1e-6);  // free fall: g dt more
  // A shorter step asks for fewer substeps of it.
  WorldSettings tuned = world.settings();
  tuned.solver.dt = 1.0 / 120.0;
  world.tune(tuned);
  EXPECT_EQ(world.substeps(), 25);
  EXPECT_NEAR(glm::length(world.velocity(0, 60) - during), 0.0, 1e-9);
  // Taken away and put back as the app's redo puts back a drawn cloth (restoreCloths, the kept
  // copy beside the cloths there are now): the fine cloth's history was kept at the short
  // substep, the sheet's since at the long one, and each is rescaled from its own.
  const Cloth kept = world.cloths()[1];
  world.removeCloth(1);
  EXPECT_EQ(world.substeps(), 4);
  EXPECT_NEAR(glm::length(world.velocity(0, 60) - during), 0.0, 1e-9);
  world.restoreCloths({world.cloths()[0], kept});
  EXPECT_EQ(world.substeps(), 25);
  EXPECT_NEAR(glm::length(world.velocity(0, 60) - during), 0.0, 1e-9);
  world.removeCloth(1);
  // Asked for more than the fabric needs, it runs what was asked.
  tuned.solver.substeps = 80;
  world.tune(tuned);
  EXPECT_EQ(world.substeps(), 80);
}

TEST(Fabric, ACutFabricBendsOnlyAlongTheLinesThatStillJoinIt) {
  World world(fabricSheet(9, 9, 0.2, 0.2));
  const std::size_t before = world.cloths()[0].rest.bending.size();
  ASSERT_EQ(world.cut(Vec3{0.1, 1.0, -0.1}, Vec3{0.1, 1.0, 0.3}, Vec3{0.0, -2.0, 0.0}), 1);
  const Cloth& c = world.cloths()[0];
  EXPECT_EQ(c.pieceCount, 2u);
  EXPECT_NE(c.rest.bending.size(), before);
  for (const BendStencil& b : c.rest.bending) {
    for (int k = 1; k < kBendStencilSize; ++k) EXPECT_EQ(c.pieceOf(b.v[k]), c.pieceOf(b.v[0]));
  }
  EXPECT_EQ(world.run(30), StepStatus::ok);
}

// A sheet bent about at random (a fixed sequence), a few particles pinned and the masses uneven.
ParticleState bentState(const ClothRest& rest) {
  ParticleState s;
  std::uint32_t seed = 12345;
  const auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<double>(seed >> 8) / static_cast<double>(1u << 24) - 0.5;
  };
  for (std::size_t i = 0; i < rest.particleCount(); ++i) {
    s.position.push_back(rest.restPosition(i) + 0.02 * Vec3{next(), next(), next()});
    s.inverseMass.push_back(i % 7 == 0 ? 0.0 : 50.0 * (1.0 + next()));
  }
  return s;
}

// The largest |C_i + alpha~ lambda_i| over the stencils: 0 where XPBD's equations all hold.
double residual(const ClothRest& rest, const ParticleState& s, const std::vector<Vec3>& lambda, double alphaTilde) {
  double worst = 0.0;
  for (std::size_t i = 0; i < rest.bending.size(); ++i) {
    const BendStencil& b = rest.bending[i];
    Vec3 c{0.0};
    for (int j = 1; j < kBendStencilSize; ++j) c += double(b.k[j]) * (s.position[b.v[j]] - s.position[b.v[0]]);
    worst = std::max(worst, glm::length(c + alphaTilde * lambda[i]));
  }
  return worst;
}

TEST(BendingBlock, OneProjectionMeetsEveryStencilsEquationAndLeavesPinsWhereTheyAre) {
  const ClothRest rest = flatRest(13);
  ParticleState s = bentState(rest);
  const ParticleState before = s;
  const double alphaTilde = 1.0 / (6.4e-5 * 1e-6);  // denim at h = 1 ms
  std::vector<Vec3> lambda(rest.bending.size(), Vec3{0.0});
  const double start = residual(rest, s, lambda, alphaTilde);
  ASSERT_GT(start, 0.1);  // the bent sheet is far from meeting them
  BendingFactor factor;
  ASSERT_TRUE(bending::prepare(factor, rest.bending, s.inverseMass, alphaTilde));
  EXPECT_LE(factor.band, 2u * 13u + 2u);  // stencils two rows apart share no particle
  bending::project(factor, s, rest.bending, lambda, alphaTilde);
  // C is linear, so one exact block step meets C + alpha~ lambda = 0 to rounding.
  EXPECT_LT(residual(rest, s, lambda, alphaTilde), 1e-9 * start);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (s.inverseMass[i] == 0.0) {
      EXPECT_EQ(s.position[i], before.position[i]) << i;
    }
  }
  // A second projection has nothing left to do.
  const ParticleState once = s;
  bending::project(factor, s, rest.bending, lambda, alphaTilde);
  for (std::size_t i = 0; i < s.position.size(); ++i)
    EXPECT_NEAR(glm::distance(s.position[i], once.position[i]), 0.0, 1e-12);
}

TEST(BendingBlock, IsFactoredAgainWhenAParticleIsPinnedAndRefusedWhenTooWide) {
  const ClothRest rest = flatRest(13);
  ParticleState s = bentState(rest);
  const double alphaTilde = 2.0e3;
  BendingFactor factor;
  ASSERT_TRUE(bending::prepare(factor, rest.bending, s.inverseMass, alphaTilde));
  // A finger takes a particle: the factor must follow, or the held particle would move.
  const std::size_t held = 6 * 13 + 6;
  s.inverseMass[held] = 0.0;
  ASSERT_TRUE(bending::prepare(factor, rest.bending, s.inverseMass, alphaTilde));
  const Vec3 where = s.position[held];
  std::vector<Vec3> lambda(rest.bending.size(), Vec3{0.0});
  const double start = residual(rest, s, lambda, alphaTilde);
  bending::project(factor, s, rest.bending, lambda, alphaTilde);
  EXPECT_EQ(s.position[held], where);
  EXPECT_LT(residual(rest, s, lambda, alphaTilde), 1e-9 * start);
  // A 128 x 128 sheet, the size issue 24 measures the drape at, is factored (1.1e9): swept stencil
  // by stencil instead, a 30 cm disc at that size hung as if it had no bending.
  const ClothRest issueSize = flatRest(128);
  BendingFactor issueFactor;
  EXPECT_TRUE(bending::prepare(issueFactor, issueSize.bending, bentState(issueSize).inverseMass, alphaTilde));
  // A 201 x 201 sheet: 40,397 stencils of half-bandwidth about 400, 6e9 to factor, over the limit.
  const ClothRest wide = flatRest(201);
  const ParticleState far = bentState(wide);
  BendingFactor wideFactor;
  EXPECT_FALSE(bending::prepare(wideFactor, wide.bending, far.inverseMass, alphaTilde));
  EXPECT_FALSE(wideFactor.usable);
}

// A 60 cm square of cotton in free space, spun at a turn a second about `axis`.
WorldSettings spinningSheet(Vec3 axis, bool lines = false) {
  WorldSettings settings = fabricSheet(24, 24, 0.6, 0.6);
  settings.gravity = Vec3{0.0};
  settings.solver.dt = 1.0 / 60.0;
  settings.solver.substeps = 4;
  settings.solver.iterations = 8;
  settings.solver.stretchSolver = lines ? StretchSolver::lines : StretchSolver::gaussSeidel;
  settings.cloths[0].initialSpin = glm::normalize(axis) * (2.0 * std::numbers::pi);
  return settings;
}

TEST(Rotation, ASpunSheetStartsTurningAboutItsCentreOfMassInBothModels) {
  const Vec3 velocity{0.1, 0.0, 0.0}, spin{0.0, 2.0 * std::numbers::pi, 0.0};
  WorldSettings settings = spinningSheet(Vec3{0, 1, 0});
  settings.cloths[0].initialVelocity = velocity;
  const auto expected = [&](const Cloth& cloth, ParticleIndex i) {
    return velocity + glm::cross(spin, cloth.state.position[i] - centreOfMass(cloth));
  };
  // The position model's velocity is its first substep's: x - x_prev, made so at the first step.
  settings.solver.substeps = 40;
  World world(settings);
  world.step();
  for (ParticleIndex i : {ParticleIndex{0}, ParticleIndex{300}, ParticleIndex{575}}) {
    const Vec3 want = expected(world.cloths()[0], i);
    EXPECT_LT(glm::length(world.velocity(0, i) - want), 0.02 * glm::length(want)) << i;
  }
  // The force model keeps its velocities: as they are made, a pinned particle's 0.
  settings.cloths[0].pins = {Pin{0, 0, std::nullopt}};
  settings.solver.model = Model::force;
  settings.cloths[0].fabric.reset();
  const World springs(settings);
  for (ParticleIndex i : {ParticleIndex{1}, ParticleIndex{300}, ParticleIndex{575}}) {
    EXPECT_LT(glm::length(springs.cloths()[0].state.velocity[i] - expected(springs.cloths()[0], i)), 1e-12) << i;
  }
  EXPECT_EQ(springs.cloths()[0].state.velocity[0], Vec3{0.0});
}

TEST(Rotation, AFreeSpinningFabricKeepsItsAngularMomentum) {
  // Each slack link moves its particles along its direction at the substep's start
  // (position::alongStart), a central force between where they were: the sweep keeps the momentum
  // to rounding (2e-8 here), where along the link's direction now it lost 38 % in these 5 s
  // (1 / sqrt(1 + (omega h)^2) a substep). The lines' solve keeps it to 2e-4: its first Newton step
  // takes a substep's whole tension at once, and the links it leaves taut enough move along n.
  for (const bool lines : {false, true}) {
    World world(spinningSheet(Vec3{0, 1, 0}, lines));
    world.step();
    const Momentum start = momentum(world);
    // The square's moment of inertia about its normal, m (w^2 + h^2) / 12 on the continuum (the
    // lattice's, 0.4 % more).
    const double mass = 0.2 * 0.36, inertia = mass * 0.72 / 12.0;
    EXPECT_NEAR(start.angular.y / (inertia * 2.0 * std::numbers::pi), 1.0, 0.05) << lines;
    world.run(299);
    const Momentum end = momentum(world);
    EXPECT_LT(glm::length(end.angular - start.angular), (lines ? 1e-3 : 1e-6) * glm::length(start.angular)) << lines;
    EXPECT_LT(glm::length(end.linear), 1e-12) << lines;
  }
}

TEST(Rotation, ASheetSpunAboutATiltedAxisWobblesAndKeepsItsAngularMomentum) {
  // Spun at 60 degrees from its normal the sheet wobbles and bends. The bending block's moves are
  // not along links (a stencil's multiplier follows its C now, not at the substep's start), so the
  // sweep keeps the momentum to 2e-7 here, not to rounding, and the lines to 0.6 %; the issue asks
  // for 1 % over 5 s.
  for (const bool lines : {false, true}) {
    World world(spinningSheet(Vec3{0.866, 0.5, 0}, lines));
    world.step();
    const Vec3 start = momentum(world).angular;
    double worst = 0.0;
    for (int second = 0; second < 5; ++second) {
      world.run(60);
      worst = std::max(worst, glm::length(momentum(world).angular - start) / glm::length(start));
    }
    EXPECT_LT(worst, lines ? 0.01 : 1e-5) << lines;
  }
}

}  // namespace
}  // namespace drape::sim
