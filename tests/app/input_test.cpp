// The app's input layer and session as functions of events: no window, no GL.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <fstream>
#include <limits>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "drape/scene/gesture.hpp"
#include "drape/sim/metrics.hpp"
#include "input.hpp"
#include "session.hpp"

namespace drape::app {
namespace {

InputEvent touch(InputEvent::Kind kind, std::int64_t finger, double x, double y) {
  InputEvent e;
  e.kind = kind;
  e.touch = 7;
  e.finger = finger;
  e.x = x;
  e.y = y;
  return e;
}

InputEvent mouse(InputEvent::Kind kind, int button, double x, double y, bool shift = false, bool ctrl = false) {
  InputEvent e;
  e.kind = kind;
  e.button = button;
  e.x = x;
  e.y = y;
  e.shift = shift;
  e.ctrl = ctrl;
  return e;
}

// The desk scene, seen by the session's framing camera: the middle of the window is on the cloth.
struct Desk {
  Session session{"desk"};
  InputMapper input{session.interaction(), session.camera()};
  Desk() { session.interaction().setCamera(session.camera(), 16.0 / 10.0); }
  std::size_t fingers() { return session.world().fingers().size(); }
};

TEST(Input, EveryTouchIsAFingerAndManyAreDownAtOnce) {
  Desk desk;
  for (int i = 0; i < 10; ++i) {
    desk.input.handle(touch(InputEvent::Kind::touchDown, i, 0.4 + 0.02 * i, 0.5), false);
  }
  EXPECT_EQ(desk.input.touchesDown(), 10);
  EXPECT_EQ(desk.fingers(), 10u);
  for (int i = 0; i < 10; ++i) desk.input.handle(touch(InputEvent::Kind::touchMove, i, 0.45 + 0.02 * i, 0.45), false);
  desk.session.step();
  for (int i = 0; i < 10; ++i) desk.input.handle(touch(InputEvent::Kind::touchUp, i, 0.45, 0.45), false);
  EXPECT_EQ(desk.input.touchesDown(), 0);
  EXPECT_EQ(desk.fingers(), 0u);
  EXPECT_TRUE(desk.input.problems().empty());
}

TEST(Input, ReusedTouchIdsMakeNewFingersAndStrayEventsAreHarmless) {
  Desk desk;
  desk.input.handle(touch(InputEvent::Kind::touchMove, 3, 0.5, 0.5), false);  // moves before any down
  desk.input.handle(touch(InputEvent::Kind::touchUp, 3, 0.5, 0.5), false);    // up without down
  ASSERT_EQ(desk.input.problems().size(), 1u);
  EXPECT_EQ(desk.input.problems().back(), "a touch ended that never began");
  desk.input.handle(touch(InputEvent::Kind::touchDown, 3, 0.5, 0.5), false);
  const std::optional<int> first = desk.input.touchFinger(7, 3);
  desk.input.handle(touch(InputEvent::Kind::touchUp, 3, 0.5, 0.5), false);
  desk.input.handle(touch(InputEvent::Kind::touchDown, 3, 0.5, 0.5), false);  // SDL reuses the id
  const std::optional<int> second = desk.input.touchFinger(7, 3);
  ASSERT_TRUE(first && second);
  EXPECT_NE(*first, *second);
  EXPECT_EQ(desk.fingers(), 1u);
  // A second down for a touch that is down lifts the first.
  desk.input.handle(touch(InputEvent::Kind::touchDown, 3, 0.52, 0.5), false);
  EXPECT_EQ(desk.fingers(), 1u);
}

TEST(Input, CoordinatesOutsideTheWindowAndNonFiniteOnesDoNotBreakAnything) {
  Desk desk;
  desk.input.handle(touch(InputEvent::Kind::touchDown, 1, 1.7, -0.4), false);
  desk.input.handle(touch(InputEvent::Kind::touchMove, 1, -3.0, 4.0), false);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  desk.input.handle(touch(InputEvent::Kind::touchDown, 2, nan, 0.5), false);
  desk.input.handle(touch(InputEvent::Kind::touchMove, 1, nan, nan), false);
  EXPECT_EQ(desk.input.touchesDown(), 1);
  for (int i = 0; i < 5; ++i) ASSERT_EQ(desk.session.step(), sim::StepStatus::ok);
}

TEST(Input, MouseDragIsAFingerUnlessThePanelsWantTheMouse) {
  Desk desk;
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.5, 0.5), true);
  EXPECT_EQ(desk.fingers(), 0u);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.5, 0.5), false);
  EXPECT_EQ(desk.fingers(), 1u);
  EXPECT_FALSE(desk.session.world().fingers().front().grips.empty());
  desk.input.handle(mouse(InputEvent::Kind::mouseMove, 0, 0.6, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.6, 0.5), false);
  EXPECT_EQ(desk.fingers(), 0u);
}

TEST(Input, ShiftParksAFingerCtrlClickLiftsItAndTheWheelRaisesIt) {
  Desk desk;
  // Two fingers far enough apart not to pinch.
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.45, 0.5, true), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.45, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.58, 0.5, true), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.58, 0.5), false);
  EXPECT_EQ(desk.input.parkedFingers(), 2);
  EXPECT_EQ(desk.fingers(), 2u);
  InputEvent wheel;
  wheel.kind = InputEvent::Kind::wheel;
  wheel.wheel = 5.0;  // 5 notches of a twentieth of the camera's distance each
  const double distance = desk.session.camera().distance;
  const double pressedAt = desk.session.world().fingers().back().position.y;
  EXPECT_DOUBLE_EQ(desk.input.liftPerNotch(), 0.05 * distance);
  desk.input.handle(wheel, true);  // over a panel: the panel scrolls, nothing lifts
  desk.input.handle(wheel, false);
  for (int i = 0; i < 60; ++i) desk.session.step();
  EXPECT_EQ(desk.session.camera().distance, distance);
  EXPECT_NEAR(desk.session.world().fingers().back().position.y - pressedAt, 5 * 0.05 * distance, 1e-9);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.46, 0.5, false, true), false);  // Ctrl-click near the first
  EXPECT_EQ(desk.input.parkedFingers(), 1);
  EXPECT_EQ(desk.fingers(), 1u);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.9, 0.9, false, true), false);  // nothing near
  EXPECT_EQ(desk.input.parkedFingers(), 1);
}

TEST(Input, CtrlClickFindsAParkedFingerByItsRingWhereverTheCameraHasGone) {
  Desk desk;
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.35, 0.5, true), false);  // off the middle
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.35, 0.5), false);
  ASSERT_EQ(desk.input.parkedFingers(), 1);
  const int id = desk.session.interaction().touches().front().id;
  EXPECT_TRUE(desk.input.parked(id));
  // Orbit a quarter turn and more: the ring is no longer where the button was let go.
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 3, 0.5, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseMove, 0, 0.9, 0.5), false);  // 1.6 rad
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 3, 0.8, 0.5), false);
  desk.session.interaction().setCamera(desk.session.camera(), 16.0 / 10.0);
  const std::optional<glm::dvec2> ring =
      desk.session.camera().project(desk.session.interaction().touches().front().position, 16.0 / 10.0);
  ASSERT_TRUE(ring);
  ASSERT_GT(std::hypot(ring->x - 0.35, ring->y - 0.5), 0.1);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.35, 0.5, false, true), false);  // where it was let go
  EXPECT_EQ(desk.input.parkedFingers(), 1);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, ring->x + 0.01, ring->y, false, true), false);  // its ring
  EXPECT_EQ(desk.input.parkedFingers(), 0);
  EXPECT_EQ(desk.fingers(), 0u);
}

TEST(Input, APointerIsOverAPanelByTheWindowsRectanglesNotLastFramesGuess) {
  const std::vector<ScreenRect> panels = {{0.7, 0.0, 1.0, 1.0}, {0.3, 0.3, 0.5, 0.5}};
  EXPECT_TRUE(overAny(panels, 0.75, 0.5));
  EXPECT_TRUE(overAny(panels, 0.4, 0.4));
  EXPECT_FALSE(overAny(panels, 0.6, 0.5));
  EXPECT_FALSE(overAny(panels, 0.4, 0.6));
  EXPECT_FALSE(overAny({}, 0.5, 0.5));
}

TEST(Input, AFailedOutlineDrawnWithTheMouseIsReported) {
  Session session("empty-table");
  InputMapper input(session.interaction(), session.camera());
  session.interaction().setCamera(session.camera(), 16.0 / 10.0);
  session.interaction().setMode(interact::Mode::create);
  input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.5, 0.5), false);  // a click
  input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.5, 0.5), false);
  ASSERT_EQ(input.problems().size(), 1u);
  EXPECT_EQ(input.problems().back().rfind("mouse: outline: ", 0), 0u) << input.problems().back();
  EXPECT_EQ(session.status.rfind("no cloth: ", 0), 0u) << session.status;
}

TEST(Input, RightDragOrbitsAndTheWheelZoomsWhenNoFingerIsDown) {
  Desk desk;
  const render::Camera before = desk.session.camera();
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 3, 0.5, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseMove, 0, 0.6, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 3, 0.6, 0.5), false);
  EXPECT_NEAR(desk.session.camera().yaw - before.yaw, 0.4, 1e-12);
  InputEvent wheel;
  wheel.kind = InputEvent::Kind::wheel;
  wheel.wheel = 2.0;
  desk.input.handle(wheel, false);
  EXPECT_NEAR(desk.session.camera().distance, before.distance / 1.21, 1e-9);
  EXPECT_EQ(desk.fingers(), 0u);
}

TEST(Input, LosingFocusMidDragLetsEverythingGo) {
  Desk desk;
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.5, 0.5), false);
  desk.input.handle(touch(InputEvent::Kind::touchDown, 1, 0.45, 0.5), false);
  desk.input.handle(mouse(InputEvent::Kind::mouseDown, 1, 0.55, 0.5, true), false);  // ignored: already dragging
  EXPECT_EQ(desk.fingers(), 2u);
  InputEvent lost;
  lost.kind = InputEvent::Kind::focusLost;
  desk.input.handle(lost, false);
  EXPECT_EQ(desk.fingers(), 0u);
  EXPECT_FALSE(desk.input.dragging());
  // The button's release arrives later, to no finger: nothing happens.
  desk.input.handle(mouse(InputEvent::Kind::mouseUp, 1, 0.5, 0.5), false);
  EXPECT_EQ(desk.fingers(), 0u);
}

TEST(FixedStepper, SpendsWholeStepsAndNeverMoreThanItsCap) {
  FixedStepper stepper(4);
  const double dt = 0.01;
  EXPECT_EQ(stepper.advance(0.025, dt), 2);  // 5 ms carried over
  EXPECT_EQ(stepper.advance(0.005, dt), 1);
  EXPECT_FALSE(stepper.fellBehind());
  EXPECT_EQ(stepper.advance(1.0, dt), 4);  // a one-second hitch costs at most 4 steps
  EXPECT_TRUE(stepper.fellBehind());
  EXPECT_EQ(stepper.advance(0.0, dt), 0);  // and its debt is dropped, not paid later
  EXPECT_EQ(stepper.advance(std::numeric_limits<double>::infinity(), dt), 0);
}

TEST(Session, ASceneThatFailsToLoadLeavesTheCurrentOneRunning) {
  Session session("desk");
  const sim::World* world = &session.world();
  const std::optional<std::string> error = session.load("no-such-scene");
  ASSERT_TRUE(error);
  EXPECT_NE(error->find("no-such-scene"), std::string::npos) << *error;
  EXPECT_EQ(session.scene().name, "desk");
  EXPECT_EQ(&session.world(), world);
  EXPECT_EQ(session.status, *error);
  EXPECT_FALSE(session.load("star"));
  EXPECT_EQ(session.scene().name, "star");
}

TEST(Session, ASceneWithNoClothOpensInCreateModeAndOneWithAClothInSticky) {
  // Nothing to hold on an empty table: the first thing to do there is draw (a new user found the
  // app waiting in Sticky mode on empty-table, dragging nothing).
  EXPECT_EQ(Session("empty-table").interaction().mode(), interact::Mode::create);
  EXPECT_EQ(Session("desk").interaction().mode(), interact::Mode::sticky);
}

TEST(Session, TheFirstViewKeepsAClothAMovingColliderCarriesInViewForTheScenesDuration) {
  // rising-sphere's ball rises from under the table and lifts the cloth a metre in the scene's 4 s.
  // Framed on the ball where it started, the cloth rose out of the top of the window by 4 s; now
  // the first view holds where the ball goes too, left of a panel covering 30 % of the window.
  Session session("rising-sphere");
  const double aspect = 16.0 / 10.0, covered = 0.3;
  session.setView(aspect, covered);
  session.resetView();
  const auto steps = static_cast<int>(std::ceil(session.scene().duration / session.world().settings().solver.dt));
  for (int i = 0; i < steps; ++i) ASSERT_EQ(session.step(), sim::StepStatus::ok);
  double highest = 0.0;
  for (const sim::Cloth& cloth : session.world().cloths()) {
    for (const sim::Vec3& x : cloth.state.position) {
      highest = std::max(highest, x.y);
      const std::optional<glm::dvec2> at = session.camera().project(x, aspect);
      ASSERT_TRUE(at);
      EXPECT_GE(at->x, 0.0);
      EXPECT_LE(at->x, 1.0 - covered);
      EXPECT_GE(at->y, 0.0);
      EXPECT_LE(at->y, 1.0);
    }
  }
  EXPECT_GT(highest, 0.9);  // it did rise
}

TEST(Session, AReplayedGesturesFirstViewHoldsWhereItsFingersGo) {
  // The tear pulls one piece 40 cm off to the right and lifts it: from the desk's own first view,
  // beside a panel covering 30 % of the window, that went behind the panel.
  Session session("desk-tear");
  const double aspect = 16.0 / 10.0, covered = 0.3;
  session.setView(aspect, covered);
  const std::vector<glm::dvec3> points =
      Session::worldPoints(scene::loadGesture(std::filesystem::path(DRAPE_ASSET_DIR) / "gestures" / "tear.json"));
  ASSERT_GE(points.size(), 6u);
  const auto allInView = [&] {
    for (const glm::dvec3& p : points) {
      const std::optional<glm::dvec2> at = session.camera().project(p, aspect);
      if (!at || at->x < 0.0 || at->x > 1.0 - covered || at->y < 0.0 || at->y > 1.0) return false;
    }
    return true;
  };
  session.resetView();
  EXPECT_FALSE(allInView()) << "the scene's own view (what this test is about)";
  session.alsoFrame(points);
  session.resetView();
  EXPECT_TRUE(allInView());
}

TEST(Session, UndoTakesBackACutAndADrawnCloth) {
  Session session("desk");
  const std::size_t grid = session.world().cloths()[0].state.position.size();  // before any cut
  interact::Interaction& hand = session.interaction();
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.5, 0.0, 0.0})));
  ASSERT_TRUE(hand.move(1, interact::Pointer::at({0.5, 0.0, 0.01})));
  ASSERT_TRUE(hand.up(1));
  EXPECT_EQ(session.world().cloths()[0].pieceCount, 2u);
  hand.setMode(interact::Mode::create);
  ASSERT_TRUE(hand.down(2, interact::Pointer::at({0.5, 0.0, 0.5})));
  for (const sim::Vec3 p : {sim::Vec3{0.8, 0.0, 0.5}, sim::Vec3{0.8, 0.0, 0.8}, sim::Vec3{0.5, 0.0, 0.8}}) {
    ASSERT_TRUE(hand.move(2, interact::Pointer::at(p)));
  }
  ASSERT_TRUE(hand.up(2));
  session.step();
  EXPECT_EQ(session.world().cloths().size(), 2u);
  ASSERT_TRUE(session.undo());  // the drawn cloth
  EXPECT_EQ(session.world().cloths().size(), 1u);
  ASSERT_TRUE(session.undo());  // the cut
  EXPECT_EQ(session.world().cloths()[0].pieceCount, 1u);
  EXPECT_EQ(session.world().cloths()[0].state.position.size(), grid);
  EXPECT_FALSE(session.undo());
}

// Sum of every particle's mass, in index order.
double totalMass(const Session& session) {
  double mass = 0.0;
  for (const sim::Cloth& cloth : session.world().cloths()) {
    for (const sim::MassReal m : cloth.state.mass) mass += m;
  }
  return mass;
}

TEST(Session, UndoingACutKeepsTheMotionSinceAndTheMassAndTheCutShowsAsASeamForAMoment) {
  Session session("desk");
  const std::size_t grid = session.world().cloths()[0].state.position.size();  // before any cut
  const double mass = totalMass(session);
  interact::Interaction& hand = session.interaction();
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.5, 0.0, 0.0})));
  ASSERT_TRUE(hand.move(1, interact::Pointer::at({0.5, 0.0, 0.01})));
  EXPECT_TRUE(session.seams().empty());  // while the swipe goes on, its stroke shows
  ASSERT_TRUE(hand.up(1));
  ASSERT_EQ(session.seams().size(), 1u);
  EXPECT_EQ(session.seams()[0].path.size(), 2u);
  ASSERT_GT(session.world().cloths()[0].state.position.size(), grid);
  // Drag the near half 20 cm along x.
  hand.setMode(interact::Mode::sticky);
  ASSERT_TRUE(hand.down(2, interact::Pointer::at({0.0, 0.0, 0.15})));
  for (int i = 1; i <= 20; ++i) {
    ASSERT_TRUE(hand.move(2, interact::Pointer::at({0.01 * i, 0.0, 0.15})));
    session.step();
  }
  ASSERT_TRUE(hand.up(2));
  session.step();
  const std::vector<sim::Vec3> moved = session.world().cloths()[0].state.position;
  ASSERT_TRUE(session.undo());
  const sim::Cloth& cloth = session.world().cloths()[0];
  ASSERT_EQ(cloth.state.position.size(), grid);
  EXPECT_EQ(cloth.pieceCount, 1u);
  for (std::size_t i = 0; i < grid; ++i) ASSERT_EQ(cloth.state.position[i], moved[i]) << i;
  EXPECT_GT(cloth.state.position[cloth.rest.index(12, 20)].x,
            -0.3 + 0.6 * 12.0 / (cloth.rest.columns - 1) + 0.1);  // still dragged
  EXPECT_EQ(totalMass(session), mass);
  // The seam fades in a second and a half of the app's time.
  session.ageSeams(1.0);
  EXPECT_EQ(session.seams().size(), 1u);
  session.ageSeams(1.0);
  EXPECT_TRUE(session.seams().empty());
}

TEST(Session, ATearRunningOverManyStepsIsUndoneAsOneWithTheMotionSince) {
  Session session("desk-tear");
  const std::size_t grid = session.world().cloths()[0].state.position.size();  // before any cut
  const double mass = totalMass(session);
  interact::Interaction& hand = session.interaction();
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.2, 0.0, 0.0})));
  ASSERT_TRUE(hand.down(2, interact::Pointer::at({0.2, 0.0, 0.0})));
  int steps = 0;
  for (; steps < 120 && session.world().cloths()[0].topology.torn < 20; ++steps) {
    ASSERT_TRUE(hand.move(1, interact::Pointer::at({-0.2 - 0.01 * steps, 0.0, 0.0})));
    ASSERT_TRUE(hand.move(2, interact::Pointer::at({0.2 + 0.01 * steps, 0.0, 0.0})));
    session.step();
  }
  ASSERT_GE(session.world().cloths()[0].topology.torn, 20u) << "it never tore";
  ASSERT_TRUE(hand.up(1));
  ASSERT_TRUE(hand.up(2));
  const std::vector<sim::Vec3> now = session.world().cloths()[0].state.position;
  ASSERT_TRUE(session.undo());
  EXPECT_EQ(session.status, "took back the last tear");
  const sim::Cloth& cloth = session.world().cloths()[0];
  ASSERT_EQ(cloth.state.position.size(), grid);
  EXPECT_EQ(cloth.topology.torn, 0u);
  EXPECT_EQ(cloth.pieceCount, 1u);
  for (std::size_t i = 0; i < grid; ++i) ASSERT_EQ(cloth.state.position[i], now[i]) << i;
  EXPECT_EQ(totalMass(session), mass);
  EXPECT_FALSE(session.undo());  // the tear was one
}

TEST(Session, RedoPutsBackACutWithTheMotionSinceAndADrawnClothAsItWas) {
  Session session("desk");
  const std::size_t grid = session.world().cloths()[0].state.position.size();  // before any cut
  const double mass = totalMass(session);
  interact::Interaction& hand = session.interaction();
  EXPECT_FALSE(session.redo());
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.5, 0.0, 0.0})));
  ASSERT_TRUE(hand.move(1, interact::Pointer::at({0.5, 0.0, 0.01})));
  ASSERT_TRUE(hand.up(1));
  for (int i = 0; i < 5; ++i) session.step();
  const std::size_t cutParticles = session.world().cloths()[0].state.position.size();
  ASSERT_GT(cutParticles, grid);
  const std::vector<sim::Vec3> atUndo = session.world().cloths()[0].state.position;
  ASSERT_TRUE(session.undo());
  // Carry the whole cloth 10 cm along x, then redo: the cut comes back where the cloth is now.
  std::vector<sim::Cloth> moved = session.world().cloths().copy();
  for (sim::Vec3& x : moved[0].state.position) x.x += 0.1;
  for (sim::Vec3& x : moved[0].state.previousPosition) x.x += 0.1;
  session.world().restoreCloths(std::move(moved));
  const std::vector<sim::Vec3> before = session.world().cloths()[0].state.position;
  ASSERT_TRUE(session.redo());
  const sim::Cloth& cut = session.world().cloths()[0];
  ASSERT_EQ(cut.state.position.size(), cutParticles);
  EXPECT_EQ(cut.pieceCount, 2u);
  EXPECT_EQ(totalMass(session), mass);
  for (std::size_t i = 0; i < grid; ++i) ASSERT_EQ(cut.state.position[i], before[i]);
  // Every particle the cut made (a copy, or one on an edge it crossed) came along the 10 cm with the
  // particles beside it, not left behind.
  for (std::size_t j = grid; j < cutParticles; ++j) {
    EXPECT_LT(glm::length(cut.state.position[j] - (atUndo[j] + sim::Vec3{0.1, 0.0, 0.0})), 1e-9) << j;
  }
  EXPECT_FALSE(session.redo());
  ASSERT_TRUE(session.undo());  // the cut again
  EXPECT_EQ(session.world().cloths()[0].state.position.size(), grid);
  // A drawn cloth: taken back, put back, and taken back again.
  hand.setMode(interact::Mode::create);
  ASSERT_TRUE(hand.down(2, interact::Pointer::at({0.5, 0.0, 0.5})));
  for (const sim::Vec3 p : {sim::Vec3{0.8, 0.0, 0.5}, sim::Vec3{0.8, 0.0, 0.8}, sim::Vec3{0.5, 0.0, 0.8}}) {
    ASSERT_TRUE(hand.move(2, interact::Pointer::at(p)));
  }
  ASSERT_TRUE(hand.up(2));
  ASSERT_EQ(session.world().cloths().size(), 2u);
  const std::size_t drawn = session.world().cloths()[1].state.position.size();
  ASSERT_TRUE(session.undo());
  EXPECT_EQ(session.world().cloths().size(), 1u);
  ASSERT_TRUE(session.redo());
  ASSERT_EQ(session.world().cloths().size(), 2u);
  EXPECT_EQ(session.world().cloths()[1].state.position.size(), drawn);
  ASSERT_TRUE(session.undo());
  EXPECT_EQ(session.world().cloths().size(), 1u);
  // Something new forgets the redo.
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(3, interact::Pointer::at({-0.5, 0.0, 0.1})));
  ASSERT_TRUE(hand.move(3, interact::Pointer::at({0.5, 0.0, 0.1})));
  ASSERT_TRUE(hand.up(3));
  EXPECT_FALSE(session.redo());
}

TEST(Session, RedoOfACutAcrossAnEarlierCutPutsEachCopyBesideItsOwnParticle) {
  // A first cut along z = 0 and its far half (the piece of particle 0) carried 15 cm along x; a
  // second cut along x = 0 across the first, undone; the far half carried 10 cm more; the second
  // cut redone. Particles on the first seam have two copies at one rest position, one on each
  // half: each copy of the second cut must come back beside its own, which moved 10 cm since the
  // undo, or a link spans those 10 cm and the strain shows it.
  Session session("desk");
  interact::Interaction& hand = session.interaction();
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.5, 0.0, 0.0})));
  ASSERT_TRUE(hand.move(1, interact::Pointer::at({0.5, 0.0, 0.001})));
  ASSERT_TRUE(hand.up(1));
  ASSERT_EQ(session.world().cloths()[0].pieceCount, 2u);
  const auto carryFarHalf = [&](double dx) {
    std::vector<sim::Cloth> cloths = session.world().cloths().copy();
    sim::Cloth& cloth = cloths[0];
    const std::vector<std::uint32_t> piece = cloth.piece;
    for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
      if (piece.empty() || piece[i] != piece[0]) continue;
      cloth.state.position[i].x += dx;
      cloth.state.previousPosition[i].x += dx;
    }
    session.world().restoreCloths(std::move(cloths));
  };
  carryFarHalf(0.15);
  const double strainBefore = sim::structuralStrain(session.world()).max;
  ASSERT_TRUE(hand.down(2, interact::Pointer::at({0.001, 0.0, -0.5})));
  ASSERT_TRUE(hand.move(2, interact::Pointer::at({0.0, 0.0, 0.5})));
  ASSERT_TRUE(hand.up(2));
  const std::size_t cutParticles = session.world().cloths()[0].state.position.size();
  const double strainCut = sim::structuralStrain(session.world()).max;
  ASSERT_TRUE(session.undo());
  carryFarHalf(0.10);
  ASSERT_TRUE(session.redo());
  ASSERT_EQ(session.world().cloths()[0].state.position.size(), cutParticles);
  EXPECT_LE(sim::structuralStrain(session.world()).max, std::max(strainCut, strainBefore) + 1e-9);
}

TEST(Session, SaveAndLoadBringBackATornClothExactly) {
  Session session("desk");
  interact::Interaction& hand = session.interaction();
  hand.setMode(interact::Mode::cut);
  ASSERT_TRUE(hand.down(1, interact::Pointer::at({-0.5, 0.0, 0.1})));
  ASSERT_TRUE(hand.move(1, interact::Pointer::at({0.5, 0.0, 0.1})));
  ASSERT_TRUE(hand.up(1));
  for (int i = 0; i < 10; ++i) session.step();
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-session-" + std::to_string(::getpid()) + ".drape.json");
  ASSERT_FALSE(session.save(file));
  const sim::Cloth saved = session.world().cloths()[0];
  Session loaded("desk");
  ASSERT_FALSE(loaded.load(file)) << loaded.status;
  // A rest length too long for the single precision rest lengths are kept in is refused by name.
  nlohmann::json document = nlohmann::json::parse(std::ifstream(file));
  std::filesystem::remove(file);
  document["cloths"][0]["stretch"][0][2] = 1e300;
  const std::filesystem::path huge = std::filesystem::temp_directory_path() / "drape-huge.drape.json";
  std::ofstream(huge) << document.dump();
  Session refused("desk");
  const std::optional<std::string> tooLong = refused.load(huge);
  std::filesystem::remove(huge);
  ASSERT_TRUE(tooLong);
  EXPECT_NE(tooLong->find("cloths.0.stretch.0"), std::string::npos) << *tooLong;
  // So is a mass single precision cannot hold (masses are kept in it too), positive but rounding
  // to 0 as much as too large.
  for (const double mass : {1e300, 1e-300}) {
    document["cloths"][0]["stretch"][0][2] = 0.01;
    document["cloths"][0]["masses"][3] = mass;
    std::ofstream(huge) << document.dump();
    Session heavy("desk");
    const std::optional<std::string> badMass = heavy.load(huge);
    std::filesystem::remove(huge);
    ASSERT_TRUE(badMass) << mass;
    EXPECT_NE(badMass->find("cloths.0.masses.3"), std::string::npos) << *badMass;
  }
  const sim::Cloth& back = loaded.world().cloths()[0];
  EXPECT_EQ(back.rest.triangles, saved.rest.triangles);
  EXPECT_EQ(back.state.position, saved.state.position);
  EXPECT_EQ(back.state.mass, saved.state.mass);
  EXPECT_EQ(back.pieceCount, 2u);
  for (int i = 0; i < 10; ++i) ASSERT_EQ(loaded.step(), sim::StepStatus::ok);
  // A snapshot that is not one is refused, and the session stays.
  const std::filesystem::path bad = std::filesystem::temp_directory_path() / "drape-bad.drape.json";
  {
    std::ofstream(bad)
        << R"({"drapeSnapshot": 1, "scene": {}, "cloths": [{"restPositions": [[0, 0, 0]], "triangles": [[0, 1, 2]]}]})";
  }
  const std::optional<std::string> error = loaded.load(bad);
  std::filesystem::remove(bad);
  ASSERT_TRUE(error);
  EXPECT_NE(error->find("cloths.0.triangles.0"), std::string::npos) << *error;
  EXPECT_EQ(loaded.world().cloths()[0].pieceCount, 2u);
}

TEST(Session, ADivergenceIsReportedTheLastGoodStateKeptAndTheSessionPaused) {
  Session session(std::filesystem::path(DRAPE_ASSET_DIR) / "extreme" / "stiff-springs.json");
  sim::StepStatus status = sim::StepStatus::ok;
  for (int i = 0; i < 600 && status == sim::StepStatus::ok; ++i) status = session.step();
  ASSERT_EQ(status, sim::StepStatus::diverged);
  EXPECT_TRUE(session.paused);
  EXPECT_EQ(session.status.rfind("diverged at step ", 0), 0u) << session.status;
  for (const sim::Vec3& x : session.world().cloths()[0].state.position) {
    ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
  }
  // It is not stuck: the next step runs (and, explicit Euler being what it is, may diverge again).
  const std::int64_t steps = session.world().stepCount();
  session.paused = false;
  if (session.step() == sim::StepStatus::ok) {
    EXPECT_EQ(session.world().stepCount(), steps + 1);
  }
  for (const sim::Vec3& x : session.world().cloths()[0].state.position) ASSERT_TRUE(std::isfinite(x.x));
}

TEST(Session, TuningAppliesWhatItCanAndRefusesWhatItCannot) {
  Session session("desk");
  sim::WorldSettings tuned = session.world().settings();
  tuned.solver.iterations = 3;
  tuned.tearing = {true, 1.2};
  tuned.colliders[0].friction.staticCoefficient = 0.1;
  ASSERT_FALSE(session.tune(tuned));
  EXPECT_EQ(session.world().settings().solver.iterations, 3);
  EXPECT_TRUE(session.world().hasStage(sim::Stage::tear));
  EXPECT_EQ(session.world().colliders()[0].settings().friction.staticCoefficient, 0.1);
  tuned.solver.dt = -1.0;
  const std::optional<std::string> refused = session.tune(tuned);
  ASSERT_TRUE(refused);
  EXPECT_EQ(*refused, "not applied: solver.dt must be a positive number of seconds");
  EXPECT_GT(session.world().settings().solver.dt, 0.0);
  tuned = session.world().settings();
  tuned.solver.model = sim::Model::force;
  EXPECT_TRUE(session.tune(tuned));
}

TEST(Session, AValueTakenAfterOneRefusedClearsTheRefusal) {
  // Typing 1.3 into the tear threshold applies "1" on the way, which is refused: once 1.3 is taken
  // the status line no longer says it was not applied. (Another message stays.)
  Session session("desk");
  sim::WorldSettings tuned = session.world().settings();
  tuned.tearing = {true, 1.0};
  ASSERT_TRUE(session.tune(tuned));
  EXPECT_EQ(session.status.rfind("not applied: ", 0), 0u) << session.status;
  tuned.tearing = {true, 1.3};
  ASSERT_FALSE(session.tune(tuned));
  EXPECT_EQ(session.status, "");
  session.status = "saved drape-save.drape.json";
  ASSERT_FALSE(session.tune(tuned));
  EXPECT_EQ(session.status, "saved drape-save.drape.json");
}

TEST(Session, AnotherModelRestartsTheSceneWithThatModelsMaterials) {
  Session session("desk");
  ASSERT_FALSE(session.setModel(sim::Model::force, sim::Integrator::rk4)) << session.status;
  const sim::WorldSettings& settings = session.world().settings();
  EXPECT_EQ(settings.solver.model, sim::Model::force);
  EXPECT_EQ(settings.solver.integrator, sim::Integrator::rk4);
  EXPECT_EQ(session.world().cloths()[0].settings.material(sim::ConstraintKind::stretch).stiffness,
            2000.0);                                                // N/m now
  EXPECT_FALSE(session.world().hasStage(sim::Stage::selfCollide));  // the force model has none
  // Its springs are stiff for so light a cloth (0.17 g a particle): omega <= sqrt(2 (4 * 2000 + 4 *
  // 2000 + 4 * 200) / 1.74e-4) = 13900 rad/s and a decay rate <= 2 (4 * 1 + 4 * 1 + 4 * 0.1) / 1.74e-4
  // = 96600 /s (Gershgorin), so RK4 wants h < 2.78 / 110500 s: the switch takes ~740 substeps of the
  // scene's 1/60 s (at the scene's 4, and at 100, the first step diverged).
  EXPECT_GE(settings.solver.substeps, 700);
  EXPECT_NE(session.status.find(std::to_string(settings.solver.substeps) + " substeps"), std::string::npos)
      << session.status;
  for (int step = 0; step < 2; ++step) ASSERT_EQ(session.step(), sim::StepStatus::ok) << session.status;
  ASSERT_FALSE(session.setModel(sim::Model::position, sim::Integrator::rk4));
  EXPECT_EQ(session.world().settings().solver.integrator, sim::Integrator::verlet);
  EXPECT_EQ(session.world().cloths()[0].settings.material(sim::ConstraintKind::stretch).stiffness, 1.0);
}

TEST(Session, AFabricRestartsEverySheetInPhysicalUnitsAndBackAsTheSceneSays) {
  Session session("desk");
  const double seedMass = session.world().cloths()[0].settings.mass;
  ASSERT_FALSE(session.setFabric(std::string("denim"))) << session.status;
  EXPECT_EQ(session.fabric(), "denim");
  const sim::ClothSettings& cloth = session.world().cloths()[0].settings;
  ASSERT_TRUE(cloth.fabric);
  EXPECT_EQ(cloth.fabric->arealDensity, 0.324);
  EXPECT_EQ(cloth.fabric->bendingRigidity, 6.4e-5);
  // The mass follows from the area: 0.324 kg/m^2 over the sheet's rest area.
  double area = 0.0;
  const sim::Cloth& made = session.world().cloths()[0];
  for (const glm::uvec3& t : made.rest.triangles) {
    area += 0.5 * glm::length(glm::cross(made.rest.restPosition(t[1]) - made.rest.restPosition(t[0]),
                                         made.rest.restPosition(t[2]) - made.rest.restPosition(t[0])));
  }
  double mass = 0.0;
  for (const sim::MassReal m : made.state.mass) mass += m;
  EXPECT_NEAR(mass, 0.324 * area, 1e-6 * mass);
  EXPECT_FALSE(made.rest.bending.empty());
  EXPECT_NE(session.status.find("denim (324 g/m^2"), std::string::npos) << session.status;
  // What a save keeps says so: the document names the fabric and no longer the seed's mass.
  const nlohmann::json document = nlohmann::json::parse(session.scene().document);
  EXPECT_EQ(document["cloths"][0]["fabric"], "denim");
  EXPECT_FALSE(document["cloths"][0].contains("mass"));
  for (int step = 0; step < 3; ++step) ASSERT_EQ(session.step(), sim::StepStatus::ok) << session.status;
  // A drawn cloth is of the same fabric.
  EXPECT_TRUE(session.interaction().settings().material.fabric);
  ASSERT_TRUE(session.setFabric(std::string("tweed")));
  EXPECT_EQ(session.fabric(), "denim");  // refused: nothing changed
  ASSERT_FALSE(session.setFabric(std::nullopt)) << session.status;
  EXPECT_TRUE(session.fabric().empty());
  EXPECT_FALSE(session.world().cloths()[0].settings.fabric);
  EXPECT_EQ(session.world().cloths()[0].settings.mass, seedMass);
}

TEST(Session, AFabricTakesTheForceModelToThePositionModelAndRefusesASceneWithoutASheet) {
  Session session("desk");
  ASSERT_FALSE(session.setModel(sim::Model::force, sim::Integrator::rk4)) << session.status;
  ASSERT_FALSE(session.setFabric(std::string("silk"))) << session.status;
  EXPECT_EQ(session.world().settings().solver.model, sim::Model::position);
  EXPECT_TRUE(session.world().cloths()[0].settings.fabric);
  Session chain("chain");
  const std::optional<std::string> refused = chain.setFabric(std::string("silk"));
  ASSERT_TRUE(refused);
  EXPECT_NE(refused->find("no sheet"), std::string::npos) << *refused;
  EXPECT_TRUE(chain.fabric().empty());
}

TEST(Session, FramingLeavesThePanelsPartOfTheWindowAndFFramesTheClothWhereverItIs) {
  Session session("desk");
  const double aspect = 16.0 / 10.0;
  const auto clothOnScreen = [&](double& left, double& right) {
    left = 1.0, right = 0.0;
    for (const sim::Vec3& x : session.world().cloths()[0].state.position) {
      const std::optional<glm::dvec2> at = session.camera().project(x, aspect);
      ASSERT_TRUE(at);
      left = std::min(left, at->x);
      right = std::max(right, at->x);
    }
  };
  double left = 0.0, right = 0.0;
  session.setView(aspect, 0.3);  // a panel over the right 30 %
  session.resetView();
  clothOnScreen(left, right);
  EXPECT_GT(left, 0.0);
  EXPECT_LT(right, 0.7);                          // clear of the panel
  EXPECT_NEAR((left + right) / 2.0, 0.35, 0.05);  // in the middle of what is left
  // Carry the cloth off to one side and look elsewhere: F brings it back into view.
  std::vector<sim::Cloth> moved = session.world().cloths().copy();
  for (sim::Vec3& x : moved[0].state.position) x += sim::Vec3{3.0, 0.0, -2.0};
  for (sim::Vec3& x : moved[0].state.previousPosition) x += sim::Vec3{3.0, 0.0, -2.0};
  session.world().restoreCloths(std::move(moved));
  session.camera().orbit(1.0, 0.2);
  const double yaw = session.camera().yaw;
  session.frameCloths();
  EXPECT_DOUBLE_EQ(session.camera().yaw, yaw);  // from where the camera looks now
  clothOnScreen(left, right);
  EXPECT_GT(left, 0.0);
  EXPECT_LT(right, 0.7);
  session.resetView();
  EXPECT_NE(session.camera().yaw, yaw);
}

TEST(Session, OrbitingBelowTheTableStopsAtItAndAnEmptyTableIsFramedAsTheDesk) {
  Session session("empty-table");
  // 80 cm of table: the view is about 2 m wide at the target, as the desk's is, not 5.
  const render::Camera& camera = session.camera();
  const auto width = [](const render::Camera& c) { return 2.0 * c.distance * std::tan(c.fieldOfView / 2.0) * 1.6; };
  EXPECT_LT(width(camera), 2.5);
  EXPECT_GT(width(camera), 1.5);
  Session desk("desk");
  EXPECT_LT(width(camera), 1.5 * width(desk.camera()));
  session.camera().orbit(0.0, -3.0);  // far below the horizon
  EXPECT_LT(session.camera().eye().y, 0.0);
  session.keepCameraAboveTable();
  EXPECT_NEAR(session.camera().eye().y, 0.01, 1e-9);
  // A scene with no table lets the camera go anywhere.
  Session hang("hang");
  hang.camera().orbit(0.0, -3.0);
  const double pitch = hang.camera().pitch;
  hang.keepCameraAboveTable();
  EXPECT_EQ(hang.camera().pitch, pitch);
}

TEST(Session, AnotherModelKeepsTheTunedWindAndDrag) {
  Session session("hang");
  sim::WorldSettings tuned = session.world().settings();
  tuned.air.velocity = sim::Vec3{1.5, 0.0, 0.5};
  tuned.air.drag = 0.7;
  ASSERT_FALSE(session.tune(tuned));
  ASSERT_FALSE(session.setModel(sim::Model::force, sim::Integrator::symplecticEuler));
  EXPECT_EQ(session.world().settings().solver.model, sim::Model::force);
  EXPECT_EQ(session.world().settings().air.velocity, tuned.air.velocity);
  EXPECT_EQ(session.world().settings().air.drag, 0.7);
}

}  // namespace
}  // namespace drape::app
