// The input layer as a function of events: pointers, planes, lifts, modes and bad events.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/interact/interaction.hpp"

namespace drape::interact {
namespace {

// A 1 m sheet lying at y = 0 around the origin, weightless so only fingers move it.
sim::WorldSettings sheet() {
  sim::WorldSettings world;
  world.gravity = Vec3{0.0};
  sim::ClothSettings cloth;
  cloth.lattice = {21, 21, 1.0, 1.0, Vec3{-0.5, 0.0, -0.5}, sim::LatticePlane::xz};
  world.cloths.push_back(cloth);
  return world;
}

render::Camera obliqueCamera() {
  render::Camera camera;
  camera.target = glm::dvec3{0.0};
  camera.yaw = 0.0;
  camera.pitch = 0.6;
  camera.distance = 2.0;
  return camera;
}

Vec3 fingerPosition(const sim::World& world, int id) { return world.finger(id)->target; }

TEST(Interaction, AScreenPointerPressesTheClothUnderIt) {
  sim::World world(sheet());
  Interaction interaction(world);
  interaction.setCamera(obliqueCamera(), 1.0);
  ASSERT_TRUE(interaction.down(1, Pointer::onScreen(0.5, 0.5)));
  const sim::Finger* finger = world.finger(1);
  ASSERT_NE(finger, nullptr);
  EXPECT_FALSE(finger->grips.empty());
  EXPECT_LT(glm::length(finger->position), 0.06);  // the camera looks at the middle of the sheet
}

TEST(Interaction, TheTablePlaneKeepsHeightAndTheViewPlaneFacesTheCamera) {
  for (FingerPlane plane : {FingerPlane::table, FingerPlane::view}) {
    sim::World world(sheet());
    Interaction interaction(world);
    interaction.setCamera(obliqueCamera(), 1.0);
    interaction.setPlane(plane);
    ASSERT_TRUE(interaction.down(1, Pointer::onScreen(0.5, 0.5)));
    ASSERT_TRUE(interaction.move(1, Pointer::onScreen(0.5, 0.3)));  // up the picture
    interaction.update(1.0 / 60.0);
    const Vec3 moved = fingerPosition(world, 1) - world.finger(1)->position;
    if (plane == FingerPlane::table) {
      EXPECT_NEAR(moved.y, 0.0, 1e-12);  // further away on the table
      EXPECT_LT(moved.z, -0.1);
    } else {
      EXPECT_GT(moved.y, 0.1);  // up in the view
      EXPECT_NEAR(glm::dot(moved, obliqueCamera().forward()), 0.0, 1e-9);
    }
  }
}

TEST(Interaction, LiftRisesAtTheLiftSpeed) {
  sim::World world(sheet());
  Interaction interaction(world);
  interaction.settings().liftSpeed = 0.6;
  ASSERT_TRUE(interaction.down(1, Pointer::at(Vec3{0.0})));
  ASSERT_TRUE(interaction.lift(1, 0.3));
  interaction.update(0.25);
  EXPECT_NEAR(fingerPosition(world, 1).y, 0.15, 1e-12);
  interaction.update(0.25);
  EXPECT_NEAR(fingerPosition(world, 1).y, 0.3, 1e-12);
  interaction.update(0.25);
  EXPECT_NEAR(fingerPosition(world, 1).y, 0.3, 1e-12);
}

TEST(Interaction, TwoHoldingFingersCloseTogetherPinchLiftAndApartComeDown) {
  sim::World world(sheet());
  Interaction interaction(world);
  interaction.settings().pinchDistance = 0.1;
  interaction.settings().pinchHeight = 0.2;
  interaction.settings().liftSpeed = 10.0;
  ASSERT_TRUE(interaction.down(1, Pointer::at(Vec3{-0.3, 0.0, 0.0})));
  ASSERT_TRUE(interaction.down(2, Pointer::at(Vec3{0.3, 0.0, 0.0})));
  interaction.update(0.1);
  EXPECT_EQ(fingerPosition(world, 1).y, 0.0);
  interaction.move(1, Pointer::at(Vec3{-0.04, 0.0, 0.0}));
  interaction.move(2, Pointer::at(Vec3{0.04, 0.0, 0.0}));
  interaction.update(0.1);
  EXPECT_NEAR(fingerPosition(world, 1).y, 0.2, 1e-12);
  EXPECT_NEAR(fingerPosition(world, 2).y, 0.2, 1e-12);
  EXPECT_TRUE(interaction.touches().front().pinched);
  interaction.move(2, Pointer::at(Vec3{0.3, 0.0, 0.0}));
  interaction.update(0.1);
  EXPECT_NEAR(fingerPosition(world, 1).y, 0.0, 1e-12);
}

TEST(Interaction, BadEventsAreRefusedWithAReason) {
  sim::World world(sheet());
  Interaction interaction(world);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(interaction.move(5, Pointer::at(Vec3{0.0})));
  EXPECT_EQ(interaction.lastError(), "finger 5 is not down");
  EXPECT_FALSE(interaction.up(5));
  EXPECT_FALSE(interaction.down(1, Pointer::at(Vec3{nan, 0.0, 0.0})));
  EXPECT_EQ(interaction.lastError(), "finger 1: the point is not finite");
  EXPECT_FALSE(interaction.down(1, Pointer::onScreen(nan, 0.5)));
  ASSERT_TRUE(interaction.down(1, Pointer::at(Vec3{0.0})));
  EXPECT_FALSE(interaction.down(1, Pointer::at(Vec3{0.0})));
  EXPECT_EQ(interaction.lastError(), "finger 1 is already down");
  EXPECT_FALSE(interaction.move(1, Pointer::onScreen(nan, nan)));
  // Out-of-window coordinates are fine (SDL does not clamp them).
  interaction.setCamera(obliqueCamera(), 1.0);
  EXPECT_TRUE(interaction.move(1, Pointer::onScreen(1.4, 0.5)));
  EXPECT_FALSE(interaction.unpin(Pointer::at(Vec3{0.0}), 0.1));
  EXPECT_EQ(interaction.lastError(), "no pin within the radius");
}

TEST(Interaction, AHundredFingersAtOnceEachHoldTheirOwn) {
  sim::World world(sheet());
  Interaction interaction(world);
  interaction.settings().radius = 0.02;
  for (int id = 0; id < 100; ++id) {
    const Vec3 at{-0.45 + 0.1 * (id % 10), 0.0, -0.45 + 0.1 * (id / 10)};
    ASSERT_TRUE(interaction.down(id, Pointer::at(at)));
  }
  EXPECT_EQ(world.fingers().size(), 100u);
  for (int id = 0; id < 100; ++id) interaction.move(id, Pointer::at(world.finger(id)->position + Vec3{0.0, 0.1, 0.0}));
  interaction.update(1.0 / 60.0);
  ASSERT_EQ(world.step(), sim::StepStatus::ok);
  interaction.cancelAll();
  EXPECT_TRUE(world.fingers().empty());
  EXPECT_TRUE(interaction.touches().empty());
}

TEST(Interaction, ADrawnClothCanBeTakenBack) {
  sim::WorldSettings settings = sheet();
  settings.cloths.clear();
  sim::World world(settings);
  Interaction interaction(world);
  interaction.settings().spacing = 0.05;
  interaction.setMode(Mode::create);
  ASSERT_TRUE(interaction.down(1, Pointer::at(Vec3{0.0, 0.0, 0.0})));
  for (const Vec3 corner : {Vec3{0.4, 0.0, 0.0}, Vec3{0.4, 0.0, 0.4}, Vec3{0.0, 0.0, 0.4}}) {
    ASSERT_TRUE(interaction.move(1, Pointer::at(corner)));
  }
  const std::uint64_t version = world.topologyVersion();
  ASSERT_TRUE(interaction.up(1));
  ASSERT_EQ(world.cloths().size(), 1u);
  EXPECT_NE(world.topologyVersion(), version);
  EXPECT_EQ(interaction.spawnedCount(), 1);
  ASSERT_TRUE(interaction.undoSpawn());
  EXPECT_TRUE(world.cloths().empty());
  EXPECT_FALSE(interaction.undoSpawn());
  // A scribble with no area makes no cloth, and says why.
  ASSERT_TRUE(interaction.down(2, Pointer::at(Vec3{0.0})));
  ASSERT_TRUE(interaction.move(2, Pointer::at(Vec3{0.3, 0.0, 0.0})));
  EXPECT_FALSE(interaction.up(2));
  EXPECT_EQ(interaction.lastError().rfind("outline: ", 0), 0u) << interaction.lastError();
  EXPECT_TRUE(world.cloths().empty());
}

TEST(Interaction, ADragTowardsTheHorizonStopsAtThreeCameraDistancesAndMovesOnAsThePointerReturns) {
  sim::World world(sheet());
  Interaction interaction(world);
  const render::Camera camera = obliqueCamera();  // 0.6 rad above the horizon, 2 m away
  interaction.setCamera(camera, 1.0);
  ASSERT_TRUE(interaction.down(1, Pointer::onScreen(0.5, 0.5)));
  const Vec3 pressed = fingerPosition(world, 1);  // on the cloth's surface, its plane's height
  const Vec3 eye = camera.eye();
  const Vec3 foot{eye.x, pressed.y, eye.z};
  // Looking 0.6 rad down with a 0.785 rad view, the horizon lies above the picture, at
  // y = 0.5 - tan(0.6) / (2 tan(0.39)) = -0.33; the pointer goes up the picture and past it.
  const double horizon = 0.5 - std::tan(0.6) / (2.0 * std::tan(camera.fieldOfView / 2.0));
  double farthest = 0.0;
  for (const double y : {0.3, 0.0, horizon + 0.01, horizon + 0.001, horizon, horizon - 0.001, -2.0}) {
    ASSERT_TRUE(interaction.move(1, Pointer::onScreen(0.6, y))) << y;
    interaction.update(1.0 / 60.0);
    const Vec3 at = fingerPosition(world, 1);
    EXPECT_NEAR(at.y, pressed.y, 1e-9) << y;  // still in the table plane
    const double reach = glm::length(at - foot);
    EXPECT_LE(reach, 3.0 * camera.distance + 1e-6) << y;
    EXPECT_GE(reach, farthest - 1e-9) << y;  // farther up the picture is never nearer
    farthest = reach;
  }
  EXPECT_NEAR(farthest, 3.0 * camera.distance, 1e-6);  // above the horizon: at the reach
  // Back down the picture, the finger comes back to where the ray meets the table.
  ASSERT_TRUE(interaction.move(1, Pointer::onScreen(0.5, 0.5)));
  interaction.update(1.0 / 60.0);
  EXPECT_LT(glm::length(fingerPosition(world, 1) - pressed), 1e-9);
}

TEST(Interaction, ADrawnOutlineSaysWhatItMadeOrWhyItMadeNothing) {
  sim::WorldSettings settings = sheet();
  settings.cloths.clear();
  sim::World world(settings);
  Interaction interaction(world);
  std::vector<std::string> told;
  interaction.tell = [&](const std::string& line) { told.push_back(line); };
  interaction.settings().spacing = 0.05;
  interaction.setMode(Mode::create);
  const auto draw = [&](int id, const std::vector<Vec3>& points) {
    EXPECT_TRUE(interaction.down(id, Pointer::at(points.front())));
    for (std::size_t i = 1; i < points.size(); ++i) EXPECT_TRUE(interaction.move(id, Pointer::at(points[i])));
    return interaction.up(id);
  };
  // A 0.4 m square at 5 cm: 9 x 9 particles.
  EXPECT_TRUE(draw(1, {Vec3{0.0}, Vec3{0.4, 0.0, 0.0}, Vec3{0.4, 0.0, 0.4}, Vec3{0.0, 0.0, 0.4}}));
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told.back(), "a cloth of " + std::to_string(world.cloths().back().state.position.size()) +
                             " particles, 0.40 m x 0.40 m");
  // A figure eight: two loops, the larger kept, and said so.
  EXPECT_TRUE(draw(2, {Vec3{0.0}, Vec3{0.6, 0.0, 0.4}, Vec3{0.6, 0.0, 0.0}, Vec3{0.0, 0.0, 0.2}}));
  ASSERT_EQ(told.size(), 2u);
  EXPECT_NE(told.back().find("the largest loop was kept"), std::string::npos) << told.back();
  // A click draws nothing, and says why.
  EXPECT_FALSE(draw(3, {Vec3{0.1, 0.0, 0.1}}));
  ASSERT_EQ(told.size(), 3u);
  EXPECT_EQ(told.back().rfind("no cloth: ", 0), 0u) << told.back();
  EXPECT_EQ(world.cloths().size(), 2u);
}

}  // namespace
}  // namespace drape::interact
