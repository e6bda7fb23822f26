// The position-based model against the seed's formulas and closed-form answers.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"
#include "solver/position_model.hpp"
#include "world_builder.hpp"

namespace drape::sim {
namespace {

TEST(PositionModel, OneProjectionRestoresRestLengthAsTheSeedWrites) {
  // Seed: dx1 = 1/2 (|x2 - x1| - r) (x2 - x1) / |x2 - x1|, dx2 = -dx1.
  std::vector<Vec3> x = {{0.0, 0.0, 0.0}, {1.2, 1.6, 0.0}};  // |x2 - x1| = 2
  const std::vector<Real> w = {1.0, 1.0};
  const RestReal r = 1.0f;
  const Vec3 d = x[1] - x[0];
  const Vec3 dx1 = 0.5 * (glm::length(d) - r) * d / glm::length(d);
  const std::vector<Vec3> expected = {x[0] + dx1, x[1] - dx1};
  position::projectDistance(x, w, {0, 1, r}, 1.0);
  EXPECT_NEAR(x[0].x, expected[0].x, 1e-6);
  EXPECT_NEAR(x[0].y, expected[0].y, 1e-6);
  EXPECT_NEAR(x[1].x, expected[1].x, 1e-6);
  EXPECT_NEAR(x[1].y, expected[1].y, 1e-6);
  EXPECT_NEAR(glm::length(x[1] - x[0]), r, 1e-6);
}

TEST(PositionModel, ProjectionWeighsByInverseMassAndStiffness) {
  // A pinned end (w = 0) does not move; the free end takes the whole correction.
  std::vector<Vec3> x = {{0.0, 0.0, 0.0}, {0.0, -3.0, 0.0}};
  position::projectDistance(x, {0.0, 2.0}, {0, 1, 1.0}, 1.0);
  EXPECT_EQ(x[0], Vec3(0.0));
  EXPECT_NEAR(x[1].y, -1.0, 1e-6);
  // Half stiffness corrects half the violation; the mass-weighted centre stays put.
  std::vector<Vec3> y = {{0.0, 0.0, 0.0}, {3.0, 0.0, 0.0}};
  const std::vector<Real> w = {1.0, 3.0};  // masses 1 and 1/3
  const Vec3 centre = (y[0] / w[0] + y[1] / w[1]) / (1.0 / w[0] + 1.0 / w[1]);
  position::projectDistance(y, w, {0, 1, 1.0}, 0.5);
  EXPECT_NEAR(glm::length(y[1] - y[0]), 2.0, 1e-6);
  const Vec3 after = (y[0] / w[0] + y[1] / w[1]) / (1.0 / w[0] + 1.0 / w[1]);
  EXPECT_NEAR(after.x, centre.x, 1e-6);
}

TEST(PositionModel, CoincidentParticlesStayFinite) {
  std::vector<Vec3> x = {{1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}};
  position::projectDistance(x, {1.0, 1.0}, {0, 1, 1.0}, 1.0);
  EXPECT_TRUE(std::isfinite(x[0].x) && std::isfinite(x[1].x));
}

// Free fall: Verlet with a Taylor start is exact for constant acceleration, y(t) = y0 - g t^2 / 2,
// up to rounding.
class FreeFall : public ::testing::TestWithParam<int> {};

TEST_P(FreeFall, MatchesTheClosedForm) {
  WorldSettings settings = test::singleParticle({0.0, 100.0, 0.0});
  settings.solver.dt = 1.0 / 60.0;
  settings.solver.substeps = GetParam();
  World world(settings);
  for (int step = 1; step <= 120; ++step) {
    ASSERT_EQ(world.step(), StepStatus::ok);
    const double t = world.time();
    const double expected = 100.0 - 0.5 * 9.81 * t * t;
    ASSERT_NEAR(world.cloths()[0].state.position[0].y, expected, 1e-9) << "step " << step;
  }
  // Velocity from the Verlet history: -g t, to first order in h.
  EXPECT_NEAR(world.velocity(0, 0).y, -9.81 * world.time(), 9.81 * world.substepDt());
}

INSTANTIATE_TEST_SUITE_P(Substeps, FreeFall, ::testing::Values(1, 4));

TEST(PositionModel, LinearDragGivesTerminalVelocity) {
  // dv/dt = -g - k v  ->  v -> -g / k.
  WorldSettings settings = test::singleParticle({0.0, 0.0, 0.0});
  settings.air.drag = 10.0;
  settings.solver.dt = 1.0 / 240.0;
  World world(settings);
  world.run(240 * 2);  // 20 time constants
  EXPECT_NEAR(world.velocity(0, 0).y, -9.81 / 10.0, 1e-6);
}

TEST(PositionModel, WindDragCarriesAParticleAtTheWindsSpeed) {
  WorldSettings settings = test::singleParticle({0.0, 0.0, 0.0});
  settings.gravity = Vec3{0.0};
  settings.air = {Vec3{3.0, 0.0, 0.0}, 5.0, 0.0};
  World world(settings);
  world.run(60 * 4);  // 20 time constants
  EXPECT_NEAR(world.velocity(0, 0).x, 3.0, 1e-6);
}

TEST(PositionModel, PinnedParticlesNeverMove) {
  WorldSettings settings = test::hangingSheet(12, 10, 2);
  settings.cloths[0].pins.push_back({6, 6, Vec3{0.0, 2.0, 0.0}});  // one pinned somewhere else
  World world(settings);
  const std::vector<Vec3> start = world.cloths()[0].state.position;
  const ClothRest& rest = world.cloths()[0].rest;
  EXPECT_EQ(start[rest.index(6, 6)], (Vec3{0.0, 2.0, 0.0}));
  for (int step = 0; step < 200; ++step) {
    ASSERT_EQ(world.step(), StepStatus::ok);
    for (const Pin& pin : settings.cloths[0].pins) {
      const ParticleIndex p = rest.index(pin.column, pin.row);
      ASSERT_EQ(world.cloths()[0].state.position[p], start[p]);
    }
  }
  // ...while the rest of the sheet has moved: on average more than 10 cm.
  Real travelled = 0.0;
  for (std::size_t i = 0; i < start.size(); ++i)
    travelled += glm::length(world.cloths()[0].state.position[i] - start[i]);
  EXPECT_GT(travelled, 0.1 * static_cast<Real>(start.size()));
}

TEST(PositionModel, MoreIterationsLessStretch) {
  const auto strainAfter = [](int iterations) {
    World world(test::hangingSheet(24, iterations, 1));
    world.run(120);
    return structuralStrain(world).max;
  };
  const double few = strainAfter(2), many = strainAfter(40);
  EXPECT_GT(few, 0.0);
  EXPECT_LT(many, 0.5 * few);
}

TEST(PositionModel, HangingSheetComesToRestBelowItsPins) {
  WorldSettings settings = test::hangingSheet(16, 20, 4);
  settings.air.drag = 1.0;
  World world(settings);
  world.run(60 * 8);
  const Cloth& cloth = world.cloths()[0];
  // At rest: the free corner hangs under the pinned edge, roughly one sheet length down, and has stopped.
  const ParticleIndex corner = cloth.rest.index(0, 15);
  EXPECT_LT(cloth.state.position[corner].y, 1.5 - 0.8);
  EXPECT_LT(glm::length(world.velocity(0, corner)), 0.05);
  // Symmetric pins, symmetric cloth: the mirror images across x = 0 match.
  for (int row = 0; row < 16; ++row) {
    const Vec3 left = cloth.state.position[cloth.rest.index(2, row)];
    const Vec3 right = cloth.state.position[cloth.rest.index(13, row)];
    EXPECT_NEAR(left.x, -right.x, 0.02);
    EXPECT_NEAR(left.y, right.y, 0.02);
  }
}

TEST(PositionModel, WindPressurePushesACurtainDownwind) {
  const auto meanZ = [](Real pressure) {
    WorldSettings settings;
    ClothSettings cloth;
    cloth.lattice = {10, 10, 1.0, 1.0, Vec3{-0.5, 2.0, 0.0}, LatticePlane::xy};
    for (int c = 0; c < 10; ++c) cloth.pins.push_back({c, 0, std::nullopt});
    settings.cloths.push_back(cloth);
    settings.air = {Vec3{0.0, 0.0, 5.0}, 0.0, pressure};
    World world(settings);
    EXPECT_EQ(world.hasStage(Stage::windPressure), pressure > 0.0);
    world.run(120);
    double sum = 0.0;
    for (const Vec3& x : world.cloths()[0].state.position) sum += x.z;
    return sum / 100.0;
  };
  EXPECT_EQ(meanZ(0.0), 0.0);  // a hanging curtain in still air has no reason to leave its plane
  EXPECT_GT(meanZ(1.0), 0.05);
}

TEST(PositionModel, ConstraintDampingBrakesMotionAlongTheConstraint) {
  // A particle falling straight away from its pin along a link of stiffness 0 and damping beta:
  // each substep keeps (1 - beta) of (u + g h), so u -> (1 - beta) g h / beta.
  const Real beta = 0.25;
  WorldSettings settings = test::verticalSpring(Model::position, Integrator::verlet, 0.01, 0.0, 1.0);
  settings.cloths[0].material(ConstraintKind::stretch).damping = beta;
  World world(settings);
  EXPECT_TRUE(world.hasStage(Stage::dampConstraints));
  EXPECT_FALSE(world.hasStage(Stage::projectConstraints));  // stiffness 0: nothing to project
  world.run(100);
  const Real h = 0.01;
  EXPECT_NEAR(world.velocity(0, 1).y, -(1.0 - beta) * 9.81 * h / beta, 1e-4);
  EXPECT_NEAR(world.velocity(0, 1).x, 0.0, 1e-6);
}

TEST(PositionModel, ThrownIntoStillAirAParticleStopsAfterExactlyV0OverK) {
  // dv/dt = -k v, v(0) = v0: it travels v0 / k in all. The damped Verlet step with its exact start
  // reproduces the exact solution at every step, whatever the step size.
  for (double dt : {1.0 / 60.0, 0.1}) {
    WorldSettings settings = test::singleParticle({0.0, 0.0, 0.0});
    settings.gravity = Vec3{0.0};
    settings.air.drag = 10.0;
    settings.solver.dt = dt;
    settings.cloths[0].initialVelocity = Vec3{1.0, 0.0, 0.0};
    World world(settings);
    world.run(static_cast<std::int64_t>(std::ceil(0.05 / dt)));
    const double t = world.time();
    EXPECT_NEAR(world.cloths()[0].state.position[0].x, 0.1 * (1.0 - std::exp(-10.0 * t)), 1e-12) << dt;
    world.run(static_cast<std::int64_t>(std::ceil(5.0 / dt)));
    EXPECT_NEAR(world.cloths()[0].state.position[0].x, 0.1, 1e-12) << dt;
  }
}

TEST(PositionModel, InitialVelocityIsKept) {
  WorldSettings settings = test::singleParticle({0.0, 0.0, 0.0});
  settings.gravity = Vec3{0.0};
  settings.cloths[0].initialVelocity = Vec3{1.0, 2.0, -3.0};
  World world(settings);
  world.run(60);
  const Vec3 x = world.cloths()[0].state.position[0];
  EXPECT_NEAR(x.x, 1.0, 1e-5);
  EXPECT_NEAR(x.y, 2.0, 1e-5);
  EXPECT_NEAR(x.z, -3.0, 1e-5);
}

}  // namespace
}  // namespace drape::sim

namespace drape::sim {
namespace {

// XPBD: a 1 kg particle hanging from a pin on a link of compliance alpha settles where the link's
// force balances its weight: elongation = alpha m g, whatever the iteration count.
TEST(Xpbd, ComplianceGivesTheStaticStretchOfASpringOfStiffnessOneOverAlpha) {
  const Real alpha = 1e-3;  // m/N, a 1000 N/m spring
  const auto elongation = [alpha](int iterations) {
    WorldSettings settings = test::verticalSpring(Model::position, Integrator::verlet, 1.0 / 60.0, 1.0, 1.0);
    settings.solver.xpbd = true;
    settings.solver.iterations = iterations;
    // Light drag to settle. (The Verlet step weighs a constant acceleration by (1 - e^-kh)/kh, exact
    // for free motion; at rest under a constraint that shaves kh/2 off the weight XPBD sees:
    // 0.4 % here.)
    settings.air.drag = 0.5;
    settings.cloths[0].material(ConstraintKind::stretch).compliance = alpha;
    World world(settings);
    world.run(3000);
    return glm::length(world.cloths()[0].state.position[1] - world.cloths()[0].state.position[0]) - 1.0;
  };
  const Real expected = alpha * 1.0 * 9.81;
  EXPECT_NEAR(elongation(5), expected, 0.02 * expected);
  EXPECT_NEAR(elongation(50), expected, 0.02 * expected);
}

TEST(Xpbd, ZeroComplianceIsRigid) {
  WorldSettings settings = test::verticalSpring(Model::position, Integrator::verlet, 1.0 / 60.0, 1.0, 1.0);
  settings.solver.xpbd = true;
  settings.solver.iterations = 1;
  World world(settings);
  world.run(60);
  EXPECT_NEAR(glm::length(world.cloths()[0].state.position[1] - world.cloths()[0].state.position[0]), 1.0, 1e-9);
}

TEST(Tethers, NoParticleEndsFartherFromAPinThanAtRestAndStretchFalls) {
  const auto hang = [](bool tethers) {
    WorldSettings settings = test::hangingSheet(24, 10, 1);
    settings.solver.tethers = tethers;
    World world(settings);
    world.run(120);
    return world;
  };
  const World tethered = hang(true);
  const Cloth& cloth = tethered.cloths()[0];
  for (ParticleIndex pin : {cloth.rest.index(0, 0), cloth.rest.index(23, 0)}) {
    for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
      // Each tether is projected in turn, so where both pins' tethers bind, the last sweep leaves a
      // sliver: within 2 %.
      EXPECT_LE(glm::length(cloth.state.position[i] - cloth.state.position[pin]),
                1.02 * glm::length(cloth.rest.restPosition(i) - cloth.rest.restPosition(pin)) + 1e-9);
    }
  }
  // Kim et al.'s point: the hanging sheet's worst stretch drops a lot for the same iterations.
  EXPECT_LT(structuralStrain(tethered).max, 0.5 * structuralStrain(hang(false)).max);
}

}  // namespace
}  // namespace drape::sim
