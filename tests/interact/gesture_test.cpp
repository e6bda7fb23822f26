// Every manipulation the issue names, as a shipped scene plus a shipped gesture script, replayed
// through the same Interaction the app uses, with a check of the physical outcome.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "drape/interact/replay.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"
#include "played.hpp"

namespace drape {
namespace {

using sim::Real;
using sim::Vec3;

using test::centroid;
using test::highest;
using test::kAssets;
using test::lowest;
using test::Played;
using test::spread;

// Area of the cloth's footprint on the table: its x-z bounding box.
Real footprint(const sim::Cloth& cloth) {
  Vec3 lo{1e9}, hi{-1e9};
  for (const Vec3& x : cloth.state.position) {
    lo = glm::min(lo, x);
    hi = glm::max(hi, x);
  }
  return (hi.x - lo.x) * (hi.z - lo.z);
}

Real totalMass(const sim::World& world) {
  Real mass = 0.0;
  for (const sim::Cloth& c : world.cloths()) mass = std::accumulate(c.state.mass.begin(), c.state.mass.end(), mass);
  return mass;
}

Real triangleArea(const sim::Cloth& cloth) {
  Real area = 0.0;
  for (const glm::uvec3& t : cloth.rest.triangles) {
    const sim::ClothRest& r = cloth.rest;
    area += 0.5 * glm::length(glm::cross(r.restPosition(t[1]) - r.restPosition(t[0]),
                                         r.restPosition(t[2]) - r.restPosition(t[0])));
  }
  return area;
}

TEST(Gesture, TranslateDragsTheClothAlongWithTheFinger) {
  Played played("desk", "translate");
  const Vec3 before = centroid(played.cloth());
  played.until();
  const Vec3 moved = centroid(played.cloth()) - before;
  // The finger went (0.3, 0, 0.1); the cloth trails it but keeps its size, so its middle follows.
  EXPECT_NEAR(moved.x, 0.3, 0.04);
  EXPECT_NEAR(moved.z, 0.1, 0.04);
  EXPECT_LT(highest(played.cloth()), 0.05);  // still lying on the table
  EXPECT_LT(sim::structuralStrain(*played.world).max, 0.1);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, TranslateOnTheScreenMovesTheClothToTheRightOfThePicture) {
  Played played("desk", "translate-screen");
  const Vec3 before = centroid(played.cloth());
  played.until();
  const Vec3 moved = centroid(played.cloth()) - before;
  // The camera looks down from +z with x to the right of the picture.
  EXPECT_GT(moved.x, 0.15);
  EXPECT_LT(std::abs(moved.z), 0.05);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, RotateTurnsTheClothAQuarterTurn) {
  Played played("desk", "rotate");
  const sim::Cloth& cloth = played.cloth();
  const auto axis = [&] {
    const Vec3 d = cloth.state.position[cloth.rest.index(20, 12)] - cloth.state.position[cloth.rest.index(3, 12)];
    return std::atan2(-d.z, d.x);
  };
  const Real before = axis();
  // The two fingers turn what they hold with them (a hand's twist), so the cloth turns whole: no
  // link is stretched on the way. (Held without turning, each finger's patch kept its heading, and
  // the cloth between them bunched into a ridge with links 2.4 times their rest length halfway.)
  double worst = 0.0;
  for (const double t : {0.5, 0.8, 1.1, 1.4, 1.7, 1.85}) {
    played.until(t);
    worst = std::max(worst, sim::structuralStrain(*played.world).max);
  }
  EXPECT_LT(worst, 0.02);
  // Just before the fingers let go (at 1.9 s) the cloth has turned with them, a quarter turn.
  EXPECT_NEAR(axis() - before, 3.14159265358979 / 2.0, 0.02);
  // Let go, it stays turned.
  played.until();
  EXPECT_NEAR(axis() - before, 3.14159265358979 / 2.0, 0.02);
  EXPECT_LT(glm::length(centroid(cloth) - Vec3{0.0, centroid(cloth).y, 0.0}), 0.05);  // about its middle
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, PinchLiftsWhatTheFingersHold) {
  Played played("desk", "pinch");
  played.until();
  const sim::World& world = *played.world;
  for (int id : {1, 2}) {
    const sim::Finger* finger = world.finger(id);
    ASSERT_NE(finger, nullptr);
    ASSERT_FALSE(finger->grips.empty());
    for (const sim::FingerGrip& grip : finger->grips) {
      EXPECT_NEAR(played.cloth().state.position[grip.particle].y, 0.205, 0.01);
    }
  }
  // The cloth hangs from the pinch: its far corners still lie on the table.
  EXPECT_LT(lowest(played.cloth()), 0.01);
  EXPECT_GT(highest(played.cloth()), 0.19);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, CrumpleGathersTheClothIntoAPile) {
  Played played("desk", "crumple");
  const Real before = spread(played.cloth());
  // Just before the six fingers let go (at 1.9 s) the cloth is gathered to under half its spread
  // (measured 0.37-0.38 of it, whatever the rounding).
  played.until(1.85);
  EXPECT_LT(spread(played.cloth()), 0.5 * before) << spread(played.cloth()) << " from " << before;
  EXPECT_GT(highest(played.cloth()), 0.03);  // folds rise out of the table
  EXPECT_EQ(sim::countIntersections(*played.world).pairs, 0u);
  // Let go, the pile falls open: its layers slide on each other (Coulomb friction between them)
  // and the compressed cloth springs back (its stretch constraints resist compression as they do
  // stretch). It comes apart without passing through itself, and stays on the table.
  played.until();
  EXPECT_EQ(sim::countIntersections(*played.world).pairs, 0u);
  EXPECT_GT(lowest(played.cloth()), 0.0);  // none under it
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, SpreadFlattensACrumpledCloth) {
  Played played("desk", "spread");
  played.until(1.3);
  const Real crumpled = highest(played.cloth());
  EXPECT_GT(crumpled, 0.03);
  played.until();
  EXPECT_LT(highest(played.cloth()), 0.02);
  EXPECT_GT(footprint(played.cloth()), 0.85 * 0.36);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

// The spread with a stretch target (solver.maxStretch, as hang2 ships): the lines through two
// fingers' patches have a span held at both ends, straight on the table, and the full Newton step
// (geometric stiffness) is as singular there as the plain one. When the fingers came down and
// pushed in it made all of a span's links but one exact and turned that one round (links 2.5 times
// their length at 2 x 8), and it threw the spans as the fingers drew out: 4 x 2 ended with links
// 1,990 times their length, 2 x 8 diverged at 2.38 s. Such lines now take the plain step, whose
// held spans are mended (lines.cpp, hasHeldSpan). The self-contact's pushes in the crumpled cloth
// still stretch a link by up to a quarter for a step, without a target too (shipped: 25 % at step
// 23), so the bound at any step is a half; at the end, flat again, every link is within the target.
TEST(Gesture, SpreadWithAStretchTargetNeverThrowsTheCloth) {
  for (const auto& [substeps, iterations] : {std::pair{"4", "2"}, std::pair{"2", "8"}}) {
    const std::string sweep = std::string(substeps) + " x " + iterations;
    Played played(Played::Files{}, kAssets / "scenes" / "desk.json", kAssets / "gestures" / "spread.json",
                  {"solver.maxStretch=0.04", std::string("solver.substeps=") + substeps,
                   std::string("solver.iterations=") + iterations});
    const sim::Cloth& cloth = played.cloth();
    const auto worstStrain = [&] {
      Real worst = 0.0;
      for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
        worst =
            std::max(worst, glm::length(cloth.state.position[c.b] - cloth.state.position[c.a]) / c.restLength - 1.0);
      }
      return worst;
    };
    Real worst = 0.0;
    while (played.world->time() < played.script.length() - 1e-9) {
      ASSERT_EQ(played.replay->step(), sim::StepStatus::ok) << sweep << " at step " << played.world->stepCount();
      worst = std::max(worst, worstStrain());
    }
    EXPECT_LT(worst, 0.5) << sweep;
    EXPECT_LT(worstStrain(), 0.04) << sweep;
    EXPECT_LT(highest(cloth), 0.02) << sweep;  // flat again
  }
}

TEST(Gesture, FoldLaysTheNearHalfOnTopOfTheFarHalf) {
  Played played("desk", "fold");
  played.until();
  const sim::Cloth& cloth = played.cloth();
  // The near third of the rows and the far third (the fold's crease runs between them). The middle
  // heights: at 32 x 32 the near edge, laid past the far one, curls down over it at the end.
  const int n = cloth.rest.columns;
  Real nearEdgeZ = 0.0;
  std::vector<Real> nearY, farY;
  for (int column = 0; column < n; ++column) {
    nearEdgeZ += cloth.state.position[cloth.rest.index(column, n - 1)].z / n;
    for (int row = 0; row < n; ++row) {
      const Real y = cloth.state.position[cloth.rest.index(column, row)].y;
      if (3 * row >= 2 * n) {
        nearY.push_back(y);
      } else if (3 * row < n) {
        farY.push_back(y);
      }
    }
  }
  const auto median = [](std::vector<Real> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(nearEdgeZ, -0.15);  // the near edge went over to the far side
  // and lies on top, a self-contact distance above
  const Real distance = played.world->settings().selfCollision.distance;
  EXPECT_NEAR(median(nearY), median(farY) + distance, 0.2 * distance);
  EXPECT_LT(highest(cloth), 0.08);  // flat, in two layers
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

// The fold at 64 x 64, its self-contact distance 0.3 of the spacing (as drape-cli bench plays it),
// twice, the distance the second time smaller by 1e-9 of itself. Friction between the layers
// answered to the whole push of a substep, and a link stretched around the fold's edge, whose push
// was the sweep taking it back out of the other layer, held the layers fast: these two runs ended
// with a link 3.3 and 5.6 times its rest length (a red patch on the fold that stayed). With the
// push bounded by the distance (self_contact.cpp), every free link ended within 10 % (2.2 and
// 1.8 %); with a sweep of the constraints after the contacts' pushes, and the contacts pushed again
// from there (World::positionSubstep), within 1.5 % (0.91 and 0.95 %).
TEST(Gesture, AFoldAt64By64EndsWithNoLinkCaughtStretchedBetweenTheLayers) {
  for (const double scale : {1.0, 1.0 - 1e-9}) {
    char distance[64];
    std::snprintf(distance, sizeof distance, "selfCollision.distance=%.17g", 0.3 * 0.6 / 63.0 * scale);
    Played played(Played::Files{}, kAssets / "scenes" / "desk.json", kAssets / "gestures" / "fold.json",
                  {"cloths.0.grid.columns=64", "cloths.0.grid.rows=64", distance});
    played.until();
    const sim::Cloth& cloth = played.cloth();
    Real worst = 0.0;
    for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
      const Real length = glm::length(cloth.state.position[c.b] - cloth.state.position[c.a]);
      worst = std::max(worst, length / c.restLength - 1.0);
    }
    EXPECT_LT(worst, 0.015) << distance;
    EXPECT_EQ(played.worstIntersections, 0u) << distance << " at step " << played.worstStep;
  }
}

TEST(Gesture, LiftRaisesTheClothOffTheTable) {
  Played played("desk", "lift");
  played.until();
  for (const sim::FingerGrip& grip : played.world->finger(1)->grips) {
    EXPECT_NEAR(played.cloth().state.position[grip.particle].y, 0.505, 1e-6);
  }
  EXPECT_GT(lowest(played.cloth()), 0.02);  // all of it hangs in the air
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, DrapeLaysTheClothOverTheBall) {
  Played played("desk-ball", "drape");
  played.until();
  const sim::Cloth& cloth = played.cloth();
  const Vec3 ball{0.5, 0.15, 0.0};
  Real closest = 1e9;
  for (const Vec3& x : cloth.state.position) closest = std::min(closest, glm::length(x - ball));
  EXPECT_GT(closest, 0.15 - 1e-3);  // nothing inside the ball
  // Resting on its top: above it, a few layers (the self-contact distance apart) thick, and down to
  // the table around it. How the bunch round the finger's patch settles is chance: over 16 runs with
  // the distance 0.1 to 2 % off, on the engine that finds a substep's pairs anew and on the one that
  // finds only the strays', the top ended 0.304 to 0.358 m high and the lowest point 5 to 42 mm.
  const Real distance = played.world->settings().selfCollision.distance;
  EXPECT_GT(highest(cloth), 0.3);
  EXPECT_LT(highest(cloth), 0.3 + 0.005 + 14 * distance);
  EXPECT_NEAR(centroid(cloth).x, 0.5, 0.1);  // centred over it
  EXPECT_LT(lowest(cloth), 0.06);            // well below the ball's middle (0.15 m)
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, PinHoldsTheCornerUpUntilItIsTakenOut) {
  Played played("desk", "pin");
  played.until(2.9);
  const sim::Cloth& cloth = played.cloth();
  const sim::ParticleIndex corner = cloth.rest.index(cloth.rest.columns - 1, cloth.rest.rows - 1);
  EXPECT_EQ(played.world->fingers().size(), 0u);
  EXPECT_TRUE(cloth.state.pinned[corner]);
  EXPECT_NEAR(glm::length(cloth.state.position[corner] - Vec3{0.3, 0.405, 0.3}), 0.0, 1e-6);
  played.until();
  EXPECT_FALSE(cloth.state.pinned[corner]);
  EXPECT_LT(cloth.state.position[corner].y, 0.08);  // it fell back onto the table (onto the cloth, maybe)
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, TearRipsTheClothAndOnePieceIsPickedUpAlone) {
  Played played("desk-tear", "tear");
  const Real mass = totalMass(*played.world);
  played.until();
  const sim::Cloth& cloth = played.cloth();
  EXPECT_GE(cloth.pieceCount, 2u);
  EXPECT_NEAR(totalMass(*played.world), mass, 1e-12);
  const sim::Finger* finger = played.world->finger(7);
  ASSERT_NE(finger, nullptr);
  ASSERT_FALSE(finger->grips.empty());
  const std::uint32_t lifted = cloth.pieceOf(finger->grips.front().particle);
  // Every other piece stayed down, none carried up with the lifted one (30 cm up): each rests on
  // the table (its lowest particle within 2 cm of it), and all of it lies low, on the table or on
  // another piece there (a flap the pull tore and flipped over the strip beside it lies on it,
  // bunched up to 6.6 cm high; the render shows it).
  int low = 0, others = 0;
  std::vector<Real> lowest(cloth.pieceCount, 1e9);
  for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
    if (cloth.pieceOf(i) == lifted) continue;
    ++others;
    low += cloth.state.position[i].y < 0.1;
    Real& l = lowest[cloth.pieceOf(i)];
    l = std::min(l, cloth.state.position[i].y);
  }
  EXPECT_GT(others, 100);
  EXPECT_EQ(low, others);
  for (std::uint32_t p = 0; p < cloth.pieceCount; ++p) {
    if (p != lifted && lowest[p] < 1e9) {
      EXPECT_LT(lowest[p], 0.02) << "piece " << p;
    }
  }
  EXPECT_NEAR(cloth.state.position[finger->grips.front().particle].y, 0.305, 1e-6);
  // Where the tear opens, the links near the crack are relaxed outside the substeps; self-contact's
  // fail-safe now takes that move too (World::changeTopology). Before, the opening's two sides
  // passed through each other for a few steps (5 pairs at step 25).
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, CutPartsTheClothAndOneHalfIsPickedUpAlone) {
  Played played("desk", "cut");
  played.until();
  const sim::Cloth& cloth = played.cloth();
  EXPECT_EQ(cloth.pieceCount, 2u);
  const std::uint32_t lifted = cloth.pieceOf(played.world->finger(2)->grips.front().particle);
  for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
    const Vec3 x = cloth.state.position[i];
    if (cloth.pieceOf(i) != lifted) {
      EXPECT_LT(x.y, 0.02);
    }
  }
  EXPECT_GT(highest(cloth), 0.25);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, DrawMakesAClothOfTheOutlinesShapeThatCanBePickedUp) {
  Played played("empty-table", "draw");
  played.until(1.5);
  ASSERT_EQ(played.world->cloths().size(), 1u);
  // A 24-gon of radius 0.2: area 24/2 r^2 sin(2 pi / 24). The stroke is simplified within a quarter
  // of the spacing (7.5 mm), which may cut a little off each side.
  const Real polygon = 12.0 * 0.04 * std::sin(2.0 * 3.14159265358979 / 24.0);
  const Real area = triangleArea(played.cloth());
  EXPECT_NEAR(area, polygon, 0.03 * polygon);
  EXPECT_LE(area, polygon * (1.0 + 1e-9));
  EXPECT_NEAR(totalMass(*played.world), 0.2 * area, 1e-9);  // the script's density times the area
  played.until();
  ASSERT_NE(played.world->finger(2), nullptr);
  EXPECT_GT(highest(played.cloth()), 0.25);
  // It never passed through itself (self-contact between triangles), at any step counted.
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(Gesture, BadEventsAreReportedAndSkipped) {
  scene::Scene scene = scene::loadScene(kAssets / "scenes" / "desk.json");
  sim::World world(scene.world);
  interact::Interaction interaction(world);
  const nlohmann::json document = nlohmann::json::parse(R"({"events": [
    {"time": 0, "type": "up", "finger": 3},
    {"time": 0, "type": "down", "finger": 1, "at": [0, 0.005, 0]},
    {"time": 0, "type": "down", "finger": 1, "at": [0.1, 0.005, 0]},
    {"time": 0.1, "type": "move", "finger": 9, "at": [0, 0, 0]},
    {"time": 0.1, "type": "pin", "finger": 4}
  ]})");
  const interact::GestureScript script = scene::parseGesture(document, "g.json");
  interact::Replay replay(world, interaction, script);
  for (int i = 0; i < 10; ++i) ASSERT_EQ(replay.step(), sim::StepStatus::ok);
  ASSERT_EQ(replay.reports().size(), 4u);
  EXPECT_EQ(replay.reports()[0], "g.json: event 0 (up at 0.000 s): finger 3 is not down; skipped");
  EXPECT_EQ(replay.reports()[1], "g.json: event 2 (down at 0.000 s): finger 1 is already down; skipped");
  EXPECT_EQ(replay.reports()[2], "g.json: event 3 (move at 0.100 s): finger 9 is not down; skipped");
  EXPECT_EQ(replay.reports()[3], "g.json: event 4 (pin at 0.100 s): finger 4 is not down; skipped");
  EXPECT_NE(world.finger(1), nullptr);  // the good event took
}

// What the app records is what the replay reads: every shipped script survives writing and reading.
TEST(GestureFile, WritingAndReadingBackKeepsEveryEvent) {
  for (const auto& entry : std::filesystem::directory_iterator(kAssets / "gestures")) {
    SCOPED_TRACE(entry.path().string());
    const interact::GestureScript script = scene::loadGesture(entry.path());
    const interact::GestureScript back = scene::parseGesture(scene::gestureDocument(script), "back.json");
    ASSERT_EQ(back.events.size(), script.events.size());
    for (std::size_t i = 0; i < script.events.size(); ++i) {
      const interact::GestureEvent& a = script.events[i];
      const interact::GestureEvent& b = back.events[i];
      EXPECT_EQ(a.time, b.time);
      EXPECT_EQ(a.type, b.type);
      EXPECT_EQ(a.finger, b.finger);
      EXPECT_EQ(a.radius, b.radius);
      EXPECT_EQ(a.pointer.has_value(), b.pointer.has_value());
      if (a.pointer && b.pointer) {
        EXPECT_EQ(a.pointer->kind, b.pointer->kind);
        EXPECT_EQ(a.pointer->world, b.pointer->world);
        EXPECT_EQ(a.pointer->screen, b.pointer->screen);
      }
    }
    EXPECT_EQ(back.camera.has_value(), script.camera.has_value());
    if (script.camera) {
      EXPECT_NEAR(back.camera->pitch, script.camera->pitch, 1e-12);
    }
    EXPECT_EQ(back.settings.radius, script.settings.radius);
    EXPECT_EQ(back.settings.pinchDistance, script.settings.pinchDistance);
    EXPECT_EQ(back.length(), script.length());
  }
}

// Issue 7's extreme case: a finger that jumps 100 m in one frame and back. The position model stays
// finite and bounded by where the finger went; the force model may blow up, but then says so.
TEST(ExtremeGesture, AFingerJumping100MetresInOneFrame) {
  for (const sim::Model model : {sim::Model::position, sim::Model::force}) {
    SCOPED_TRACE(sim::name(model));
    scene::Scene scene = scene::loadScene(kAssets / "scenes" / "desk.json");
    scene.world.solver.model = model;
    scene.world.solver = sim::consistent(scene.world.solver);  // the force model: no line solve
    // Self-contact between triangles under this jump takes minutes and ends with a particle 104 m
    // out (issue 21's note: open); the particle method is what this test holds to the bound.
    scene.world.selfCollision.method = sim::SelfContactMethod::particles;
    scene.world.selfCollision.distance = 0.02;
    if (model == sim::Model::force) {
      scene.world.solver.integrator = sim::Integrator::symplecticEuler;
      scene.world.selfCollision.enabled = false;
      for (sim::ConstraintKind kind : sim::kConstraintKinds) scene.world.cloths[0].material(kind) = {500.0, 0.5};
    }
    sim::World world(scene.world);
    const double dt = scene.world.solver.dt;
    const nlohmann::json document = {
        {"events",
         {{{"time", 0.2}, {"type", "down"}, {"finger", 1}, {"at", {0.0, 0.005, 0.0}}},
          {{"time", 0.5}, {"type", "move"}, {"finger", 1}, {"at", {0.0, 0.005, 0.0}}},
          {{"time", 0.5 + dt}, {"type", "move"}, {"finger", 1}, {"at", {100.0, 0.005, 0.0}}},
          {{"time", 1.5}, {"type", "move"}, {"finger", 1}, {"at", {100.0, 0.005, 0.0}}},
          {{"time", 1.5 + dt}, {"type", "move"}, {"finger", 1}, {"at", {0.0, 0.005, 0.0}}},
          {{"time", 1.7}, {"type", "up"}, {"finger", 1}}}}};
    const interact::GestureScript script = scene::parseGesture(document, "jump.json");
    interact::Interaction interaction(world);
    interact::Replay replay(world, interaction, script);
    sim::StepStatus status = sim::StepStatus::ok;
    Real farthest = 0.0;
    while (status == sim::StepStatus::ok && world.time() < 3.0) {
      status = replay.step();
      for (const Vec3& x : world.cloths()[0].state.position) farthest = std::max(farthest, glm::length(x));
    }
    for (const Vec3& x : world.cloths()[0].state.position) {
      ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
    }
    if (model == sim::Model::position) {
      EXPECT_EQ(status, sim::StepStatus::ok);
      // Never far beyond the finger: the particles it drags at 6 km/s run on past it for a moment, by
      // 2.15 m at 32 x 32 (under 2 m at 24 x 24); within four times the cloth's 0.6 m width.
      EXPECT_LT(farthest, 100.0 + 4 * 0.6);
    } else if (status == sim::StepStatus::diverged) {
      EXPECT_GT(world.divergence()->step, 0);
    }
  }
}

}  // namespace
}  // namespace drape
