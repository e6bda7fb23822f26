// Scene files: the shipped scenes, overrides, and what the reader refuses.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/fabric.hpp"
#include "drape/scene/output.hpp"
#include "drape/scene/scene.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::scene {
namespace {

using nlohmann::json;

TEST(ShippedScenes, AllLoadAndBuildAWorld) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(sceneDirectory())) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene scene = loadScene(entry.path());
    EXPECT_FALSE(scene.description.empty());
    sim::World world(scene.world);
    EXPECT_EQ(world.run(10), sim::StepStatus::ok);
    ++count;
  }
  EXPECT_GE(count, 3);
}

// Every shipped scene on its own for its whole duration (issue 21: no cloth through itself at any
// step of any shipped scene; rising-sphere's folds passed through each other for three steps at
// 1.5 s, 4 triangle pairs at most, until it had self-contact). Counted exactly at every step.
TEST(ShippedScenes, RunTheirWholeDurationWithoutDivergingTearingApartOrPassingThroughThemselves) {
  for (const auto& entry : std::filesystem::directory_iterator(sceneDirectory())) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene scene = loadScene(entry.path());
    sim::World world(scene.world);
    const auto steps = static_cast<std::int64_t>(std::ceil(scene.duration / scene.world.solver.dt));
    std::size_t worst = sim::countIntersections(world).pairs;
    std::int64_t worstStep = 0;
    for (std::int64_t step = 1; step <= steps; ++step) {
      ASSERT_EQ(world.step(), sim::StepStatus::ok) << "at step " << step;
      const std::size_t pairs = sim::countIntersections(world).pairs;
      if (pairs > worst) {
        worst = pairs;
        worstStep = step;
      }
    }
    EXPECT_EQ(worst, 0u) << "intersecting triangle pairs at step " << worstStep;
    // No structural edge ends more than a quarter longer than its rest length.
    EXPECT_LT(sim::structuralStrain(world).max, 0.25);
    // Nothing ends inside a collider deeper than a millimetre.
    for (const sim::Cloth& cloth : world.cloths()) {
      for (const sim::Vec3& x : cloth.state.position) {
        for (const sim::Collider& collider : world.colliders()) EXPECT_GT(collider.distance(x, 1.0).distance, -1e-3);
      }
    }
  }
}

sim::World settle(const std::string& name, const std::vector<std::string>& overrides = {}) {
  const Scene scene = loadScene(resolveScenePath(name), overrides);
  sim::World world(scene.world);
  EXPECT_EQ(world.run(static_cast<std::int64_t>(std::ceil(scene.duration / scene.world.solver.dt))),
            sim::StepStatus::ok);
  return world;
}

TEST(ShippedScenes, SlopeHoldsItsClothBelowTheFrictionAngleAndNotAbove) {
  // How far the cloth's centre moves downhill (-x on this slope) between 1.5 s, when it has landed,
  // and 3 s.
  const auto creep = [](const std::vector<std::string>& overrides) {
    std::vector<std::string> landed = overrides, later = overrides;
    landed.push_back("duration=1.5");
    later.push_back("duration=3");
    const sim::World a = settle("slope", landed), b = settle("slope", later);
    const sim::ParticleIndex centre = a.cloths()[0].rest.index(8, 8);
    return a.cloths()[0].state.position[centre].x - b.cloths()[0].state.position[centre].x;
  };
  EXPECT_LT(std::abs(creep({})), 1e-3);  // tan(20 deg) = 0.36 < mu = 0.5: it stays put
  EXPECT_GT(creep({"colliders.0.friction={\"static\":0.2,\"kinetic\":0.2}"}), 0.3);  // mu = 0.2: it slides
}

// The fold scene holds a cloth along its middle row (24 of 48); the rows above it but the two
// nearest are the half that topples over, those below it but the nearest the half that hangs.
// Returns the closest distance between the two halves and the upper half's top.
struct Fold {
  double closest;
  double upperTop;
};

Fold measureFold(const sim::World& world) {
  const sim::Cloth& cloth = world.cloths()[0];
  Fold fold{1.0, -1.0};
  const int held = cloth.rest.rows / 2;
  for (int r = 0; r <= held - 3; ++r) {
    for (int c = 0; c < cloth.rest.columns; ++c) {
      const sim::Vec3 a = cloth.state.position[cloth.rest.index(c, r)];
      fold.upperTop = std::max(fold.upperTop, a.y);
      for (int r2 = held + 2; r2 < cloth.rest.rows; ++r2) {
        for (int c2 = 0; c2 < cloth.rest.columns; ++c2) {
          fold.closest = std::min(fold.closest, glm::length(a - cloth.state.position[cloth.rest.index(c2, r2)]));
        }
      }
    }
  }
  return fold;
}

TEST(ShippedScenes, FoldSettlesInTwoLayersThatDoNotPassThroughEachOther) {
  const sim::World world = settle("fold");
  const double distance = world.settings().selfCollision.distance;
  const sim::Cloth& cloth = world.cloths()[0];
  ASSERT_EQ(cloth.rest.rows % 2, 0);
  const double heldAt = cloth.state.position[cloth.rest.index(0, cloth.rest.rows / 2)].y;
  const Fold folded = measureFold(world);
  EXPECT_LT(folded.upperTop, heldAt);         // the upper half has toppled over the held line
  EXPECT_GT(folded.closest, 0.5 * distance);  // and lies against the lower half, not in it
  EXPECT_LT(folded.closest, 0.15);            // side by side: the fold loop keeps them 2.8 cm apart
}

TEST(ShippedScenes, ARisingBallLiftsTheCloth) {
  const sim::World world = settle("rising-sphere");
  double highest = 0.0;
  for (const sim::Vec3& x : world.cloths()[0].state.position) highest = std::max(highest, x.y);
  // The ball's top is at -0.3 + 0.3 + 0.25 * 4 = 1.0 m after 4 s; the cloth rides on it.
  EXPECT_NEAR(highest, 1.0 + world.cloths()[0].settings.thickness, 0.02);
}

TEST(ShippedScenes, ResolveByName) {
  EXPECT_EQ(resolveScenePath("hang"), sceneDirectory() / "hang.json");
  EXPECT_EQ(loadScene(resolveScenePath("chain")).world.cloths.at(0).lattice.rows, 1);
}

json minimal() {
  return json::parse(R"({"cloths": [{"grid": {"columns": 4, "rows": 3}, "pins": [{"particle": [0, 0]}]}]})");
}

TEST(SceneReader, AbsentKeysTakeTheDocumentedDefaults) {
  const Scene scene = parseScene(minimal(), "mem.json");
  EXPECT_EQ(scene.name, "mem");
  EXPECT_EQ(scene.world.solver.model, sim::Model::position);
  EXPECT_DOUBLE_EQ(scene.world.solver.dt, 1.0 / 60.0);
  EXPECT_DOUBLE_EQ(scene.world.gravity.y, -9.81);
  const sim::ClothSettings& cloth = scene.world.cloths.at(0);
  EXPECT_EQ(cloth.lattice.plane, sim::LatticePlane::xz);
  EXPECT_DOUBLE_EQ(cloth.mass, 1.0);
  EXPECT_DOUBLE_EQ(cloth.material(sim::ConstraintKind::stretch).stiffness, 1.0);
  ASSERT_EQ(cloth.pins.size(), 1u);
  EXPECT_FALSE(cloth.pins[0].position.has_value());
}

TEST(SceneReader, ForceModelMaterialsAreSprings) {
  json document = minimal();
  applyOverride(document, "solver.model=force");
  applyOverride(document, "solver.integrator=rk4");
  applyOverride(document, "cloths.0.stretch.stiffness=5000");
  const Scene scene = parseScene(document, "mem.json");
  EXPECT_EQ(scene.world.solver.integrator, sim::Integrator::rk4);
  EXPECT_DOUBLE_EQ(scene.world.cloths[0].material(sim::ConstraintKind::stretch).stiffness, 5000.0);
}

TEST(Overrides, SetNumbersStringsArraysAndCreateMissingObjects) {
  json document = minimal();
  applyOverride(document, "cloths.0.grid.columns=64");
  applyOverride(document, "solver.model=force");
  applyOverride(document, "gravity=[0,-1.62,0]");
  applyOverride(document, "cloths.0.pins.0.particle=[3,2]");
  EXPECT_EQ(document["cloths"][0]["grid"]["columns"], 64);
  EXPECT_EQ(document["solver"]["model"], "force");
  EXPECT_EQ(document["gravity"][1], -1.62);
  EXPECT_EQ(document["cloths"][0]["pins"][0]["particle"], json::parse("[3,2]"));
}

std::string errorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(SceneReader, ASpinIsReadInDegreesASecondAndBoundedLikeAColliders) {
  json document = minimal();
  EXPECT_EQ(parseScene(document, "s.json").world.cloths.at(0).initialSpin, sim::Vec3{0.0});
  applyOverride(document, "cloths.0.spin=[0,360,-90]");
  const sim::Vec3 spin = parseScene(document, "s.json").world.cloths.at(0).initialSpin;
  EXPECT_DOUBLE_EQ(spin.y, 2.0 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(spin.z, -0.5 * std::numbers::pi);
  applyOverride(document, "cloths.0.spin=[0,40000,0]");
  EXPECT_NE(errorOf([&] { parseScene(document, "s.json"); }).find("s.json: cloths.0.spin"), std::string::npos);
}

TEST(SceneReader, AFabricIsAPresetOrItsNumbersAndRefusesWhatItReplaces) {
  json document = minimal();
  applyOverride(document, "cloths.0.fabric=denim");
  const sim::ClothSettings denim = parseScene(document, "s.json").world.cloths.at(0);
  ASSERT_TRUE(denim.fabric.has_value());
  EXPECT_DOUBLE_EQ(denim.fabric->arealDensity, 0.324);
  EXPECT_DOUBLE_EQ(denim.fabric->bendingRigidity, 6.4e-5);

  document = minimal();
  document["cloths"][0]["fabric"] = json::parse(R"({"preset": "silk", "bendingRigidity": 4e-6})");
  const sim::ClothSettings silk = parseScene(document, "s.json").world.cloths.at(0);
  EXPECT_DOUBLE_EQ(silk.fabric->arealDensity, fabricPreset("silk")->arealDensity);
  EXPECT_DOUBLE_EQ(silk.fabric->bendingRigidity, 4e-6);

  document = minimal();
  applyOverride(document, "cloths.0.fabric=tweed");
  EXPECT_NE(
      errorOf([&] { parseScene(document, "s.json"); }).find("s.json: cloths.0.fabric: expected a fabric preset (silk"),
      std::string::npos);
  applyOverride(document, "cloths.0.fabric=cotton");
  applyOverride(document, "cloths.0.mass=2");
  EXPECT_NE(errorOf([&] { parseScene(document, "s.json"); }).find("s.json: cloths.0.mass: expected no \"mass\""),
            std::string::npos);
  document = minimal();
  document["cloths"][0]["fabric"] = json::parse(R"({"bendingRigidity": -1})");
  EXPECT_NE(errorOf([&] { parseScene(document, "s.json"); }).find("cloths.0.fabric.bendingRigidity"),
            std::string::npos);
  document = minimal();
  applyOverride(document, "cloths.0.fabric=cotton");
  applyOverride(document, "solver.model=force");
  applyOverride(document, "solver.integrator=rk4");
  EXPECT_NE(
      errorOf([&] { parseScene(document, "s.json"); }).find("cloths.0.fabric: expected no fabric in the force model"),
      std::string::npos);
}

TEST(Overrides, BadAssignmentsAreErrorsNamingTheOption) {
  json document = minimal();
  EXPECT_EQ(errorOf([&] { applyOverride(document, "solver.dt"); }),
            "--set solver.dt: expected path=value, e.g. cloths.0.grid.columns=64");
  EXPECT_EQ(errorOf([&] { applyOverride(document, "cloths.3.mass=1"); }),
            "--set cloths.3.mass=1: 3 is not an index of an array of 1");
  EXPECT_EQ(errorOf([&] { applyOverride(document, "cloths.0.grid.columns.x=1"); }),
            "--set cloths.0.grid.columns.x=1: cannot go into 4 at x");
}

struct BadScene {
  const char* override;
  const char* message;
};

void PrintTo(const BadScene& c, std::ostream* os) { *os << c.override; }

class SceneErrors : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneErrors, NameTheFileTheKeyAndWhatWasExpected) {
  json document = minimal();
  applyOverride(document, GetParam().override);
  EXPECT_EQ(errorOf([&] { parseScene(document, "s.json"); }), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SceneErrors,
    ::testing::Values(
        BadScene{"clothes=[]", "s.json: clothes: unknown key"},
        BadScene{"cloths.0.grid.colums=3", "s.json: cloths.0.grid.colums: unknown key"},
        BadScene{"solver.dt=fast", "s.json: solver.dt: expected a number >= 1e-06 and <= 1 (s), got \"fast\""},
        BadScene{"solver.dt=0", "s.json: solver.dt: expected a number >= 1e-06 and <= 1 (s), got 0"},
        BadScene{"cloths.0.mass=-1", "s.json: cloths.0.mass: expected a number >= 1e-06 and <= 1000000 (kg), got -1"},
        BadScene{"cloths.0.grid.width=0", "s.json: cloths.0.grid.width: expected a number > 0 and <= 1000 (m), got 0"},
        BadScene{"cloths.0.grid.columns=2.5",
                 "s.json: cloths.0.grid.columns: expected an integer from 1 to 4096, got 2.5"},
        BadScene{"cloths.0.grid.rows=5000", "s.json: cloths.0.grid.rows: expected an integer from 1 to 4096, got 5000"},
        BadScene{"cloths.0.pins.0.particle=[4,0]",
                 "s.json: cloths.0.pins.0.particle: expected [column, row] inside the 4 x 3 grid, got [4,0]"},
        BadScene{"cloths.0.pins.0.particle=\"corner\"",
                 "s.json: cloths.0.pins.0.particle: expected [column, row] inside the 4 x 3 grid, got \"corner\""},
        BadScene{"gravity=[0,-9.81]",
                 "s.json: gravity: expected [x, y, z]: three numbers within +-1000 (m/s^2), got [0,-9.81]"},
        BadScene{"solver.model=implicit",
                 "s.json: solver.model: expected one of \"position\" \"force\", got \"implicit\""},
        BadScene{"solver.integrator=rk4",
                 "s.json: solver.integrator: expected \"verlet\" for the position model (the others belong to "
                 "\"model\": \"force\"), got \"rk4\""},
        BadScene{"cloths.0.stretch.stiffness=2",
                 "s.json: cloths.0.stretch.stiffness: expected a number >= 0 and <= 1 (fraction corrected per "
                 "sweep), got 2"},
        BadScene{"solver=[]", "s.json: solver: expected an object { ... }, got []"},
        BadScene{"cloths.0.grid={\"columns\":2048,\"rows\":1024}",
                 "s.json: cloths.0.grid: 2048 x 1024 particles pass the limit of 1048576 particles over all cloths"}));

TEST(SceneErrors, NonFiniteNumbersAreRefused) {
  // JSON has no NaN or infinity literals; a number too large for a double is the way one sneaks in.
  json document = minimal();
  document["solver"]["dt"] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(errorOf([&] { parseScene(document, "s.json"); }),
            "s.json: solver.dt: expected a number >= 1e-06 and <= 1 (s), got a non-finite number");
  document = minimal();
  document["gravity"] = {0.0, std::nan(""), 0.0};
  EXPECT_NE(errorOf([&] { parseScene(document, "s.json"); }).find("s.json: gravity: expected [x, y, z]"),
            std::string::npos);
}

}  // namespace
}  // namespace drape::scene

namespace drape::scene {
namespace {

// assets/extreme: stiff, huge steps, many iterations, hurricane, one particle, coincident particles,
// heavy gravity, a mass ratio of 1e6 between neighbours, every constraint torn. The position model must stay finite and
// bounded in every one; the force model may diverge, but then the world must say so (at which step) and hold the last
// good, finite state.
TEST(ExtremeScenes, PositionModelStaysFiniteAndBoundedForceModelReportsDivergence) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(sceneDirectory().parent_path() / "extreme")) {
    SCOPED_TRACE(entry.path().string());
    const Scene scene = loadScene(entry.path());
    sim::World world(scene.world);
    const auto mass = [&world] {
      double total = 0.0;
      for (const sim::Cloth& cloth : world.cloths()) {
        for (double m : cloth.state.mass) total += m;
      }
      return total;
    };
    const double massBefore = mass();
    const sim::StepStatus status =
        world.run(static_cast<std::int64_t>(std::ceil(scene.duration / scene.world.solver.dt)));
    if (scene.world.solver.model == sim::Model::position) {
      EXPECT_EQ(status, sim::StepStatus::ok);
    } else {
      EXPECT_EQ(status, sim::StepStatus::diverged);
      ASSERT_TRUE(world.divergence().has_value());
      EXPECT_GT(world.divergence()->step, 0);
    }
    for (const sim::Cloth& cloth : world.cloths()) {
      for (const sim::Vec3& x : cloth.state.position) {
        EXPECT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
        if (scene.world.solver.model == sim::Model::position) {
          EXPECT_LT(glm::length(x), 100.0);
        }
      }
    }
    EXPECT_NEAR(mass(), massBefore, 1e-12 * massBefore);  // tearing splits particles, never loses them
    ++count;
  }
  EXPECT_GE(count, 10);
}

}  // namespace
}  // namespace drape::scene

namespace drape::scene {
namespace {

TEST(SceneReader, XpbdTethersAndComplianceBelongToThePositionModel) {
  json document = minimal();
  applyOverride(document, "solver.xpbd=true");
  applyOverride(document, "solver.tethers=true");
  applyOverride(document, "cloths.0.stretch={\"compliance\":1e-6}");
  const Scene scene = parseScene(document, "s.json");
  EXPECT_TRUE(scene.world.solver.xpbd && scene.world.solver.tethers);
  EXPECT_DOUBLE_EQ(scene.world.cloths[0].material(sim::ConstraintKind::stretch).compliance, 1e-6);
  applyOverride(document, "solver.xpbd=false");
  EXPECT_EQ(
      errorOf([&] { parseScene(document, "s.json"); }),
      "s.json: cloths.0.stretch.compliance: expected no compliance unless \"solver\": {\"xpbd\": true}, got 1e-06");
  json force = minimal();
  applyOverride(force, "solver.model=force");
  applyOverride(force, "solver.tethers=true");
  EXPECT_EQ(errorOf([&] { parseScene(force, "s.json"); }),
            "s.json: solver.tethers: expected false for the force model (it belongs to the position model), got true");
}

TEST(SceneReader, TheStretchSolverIsNamed) {
  EXPECT_EQ(parseScene(minimal(), "s.json").world.solver.stretchSolver, sim::StretchSolver::gaussSeidel);
  json document = minimal();
  applyOverride(document, "solver.stretchSolver=\"lines\"");
  EXPECT_EQ(parseScene(document, "s.json").world.solver.stretchSolver, sim::StretchSolver::lines);
  applyOverride(document, "solver.stretchSolver=\"jacobi\"");
  EXPECT_EQ(errorOf([&] { parseScene(document, "s.json"); }),
            "s.json: solver.stretchSolver: expected one of \"gauss-seidel\" \"lines\", got \"jacobi\"");
  // The key it replaced, and the four it took the place of with maxStretch, say what to write instead.
  json old = minimal();
  applyOverride(old, "solver.lines=true");
  EXPECT_EQ(errorOf([&] { parseScene(old, "s.json"); }),
            "s.json: solver.lines: expected \"stretchSolver\": \"lines\" or \"gauss-seidel\" instead, got true");
  for (const char* key : {"geometricStiffness", "tethersBetweenSteps", "extraLineSteps", "stretchTolerance"}) {
    json older = minimal();
    applyOverride(older, std::string("solver.") + key + "=1");
    EXPECT_EQ(errorOf([&] { parseScene(older, "s.json"); }),
              std::string("s.json: solver.") + key +
                  ": expected \"maxStretch\" instead (the engine picks what works to it: docs/scenes.md), got 1");
  }
}

TEST(SceneReader, AFabricsSubstepSpeedIsReadInMetresASecondAndRefusedOutsideItsRange) {
  EXPECT_DOUBLE_EQ(parseScene(minimal(), "s.json").world.solver.fabricSubstepSpeed, 7.5);
  json document = minimal();
  applyOverride(document, "solver.fabricSubstepSpeed=0");
  EXPECT_DOUBLE_EQ(parseScene(document, "s.json").world.solver.fabricSubstepSpeed, 0.0);
  for (const char* value : {"-1", "1e5", "\"fast\""}) {
    json out = minimal();
    applyOverride(out, std::string("solver.fabricSubstepSpeed=") + value);
    EXPECT_NE(errorOf([&] { parseScene(out, "s.json"); }).find("s.json: solver.fabricSubstepSpeed: expected "),
              std::string::npos)
        << value;
  }
}

TEST(SceneReader, AStretchTargetNeedsTheLinesARigidClothAndARange) {
  json document = minimal();
  applyOverride(document, "solver.stretchSolver=\"lines\"");
  applyOverride(document, "solver.maxStretch=0.02");
  EXPECT_DOUBLE_EQ(parseScene(document, "s.json").world.solver.maxStretch, 0.02);
  EXPECT_EQ(parseScene(minimal(), "s.json").world.solver.maxStretch, 0.0);
  json without = document;
  applyOverride(without, "solver.stretchSolver=\"gauss-seidel\"");
  EXPECT_EQ(errorOf([&] { parseScene(without, "s.json"); }),
            "s.json: solver.maxStretch: expected 0 unless \"stretchSolver\" is \"lines\" (the line solve works to "
            "it), got 0.02");
  json compliant = document;
  applyOverride(compliant, "solver.xpbd=true");
  EXPECT_EQ(errorOf([&] { parseScene(compliant, "s.json"); }),
            "s.json: solver.maxStretch: expected 0 with \"xpbd\" (a compliant cloth stretches as its compliance says, "
            "not to a target), got 0.02");
  for (const char* value : {"-0.1", "1.5"}) {
    json out = document;
    applyOverride(out, std::string("solver.maxStretch=") + value);
    EXPECT_NE(errorOf([&] { parseScene(out, "s.json"); }).find("s.json: solver.maxStretch: "), std::string::npos)
        << value;
  }
  // The force model has no lines: the keys are refused there, and dropped when a scene switches to it.
  json force = minimal();
  applyOverride(force, "solver.model=force");
  applyOverride(force, "solver.stretchSolver=\"lines\"");
  EXPECT_NE(errorOf([&] { parseScene(force, "s.json"); }).find("s.json: solver.stretchSolver: "), std::string::npos);
  const Scene switched = withModel(parseScene(document, "s.json"), sim::Model::force, sim::Integrator::verlet);
  EXPECT_EQ(switched.world.solver.maxStretch, 0.0);
  EXPECT_EQ(switched.world.solver.stretchSolver, sim::StretchSolver::gaussSeidel);
  EXPECT_EQ(switched.document.find("maxStretch"), std::string::npos);
  EXPECT_EQ(switched.document.find("stretchSolver"), std::string::npos);
}

TEST(Scene, SwitchingToTheForceModelTakesTheSubstepsItsSpringsNeed) {
  // 12 particles of 0.83 g on the force model's 2000 N/m springs: a few hundred substeps of 1/60 s.
  json light = minimal();
  applyOverride(light, "cloths.0.mass=0.01");
  const Scene scene = parseScene(light, "s.json");
  for (const sim::Integrator integrator : {sim::Integrator::symplecticEuler, sim::Integrator::rk4}) {
    const Scene switched = withModel(scene, sim::Model::force, integrator);
    const sim::SolverSettings& solver = switched.world.solver;
    sim::World world(switched.world);
    const double longest = 0.9 * world.stableForceSubstep();
    EXPECT_LE(solver.dt / solver.substeps, longest) << sim::name(integrator);        // enough ...
    EXPECT_GT(solver.dt / (solver.substeps - 1), longest) << sim::name(integrator);  // ... and no more
    EXPECT_NE(switched.document.find("\"substeps\":" + std::to_string(solver.substeps)), std::string::npos);
    EXPECT_EQ(world.run(60), sim::StepStatus::ok) << sim::name(integrator);
    // At the scene's own substeps the same cloth blows up.
    sim::WorldSettings few = switched.world;
    few.solver.substeps = scene.world.solver.substeps;
    sim::World unstable(few);
    EXPECT_EQ(unstable.run(60), sim::StepStatus::diverged) << sim::name(integrator);
  }
  // The position model keeps the scene's substeps.
  EXPECT_EQ(withModel(scene, sim::Model::position, sim::Integrator::verlet).world.solver.substeps,
            scene.world.solver.substeps);
}

TEST(Snapshot, AClothFarFromTheOriginComesBackOffsetForOffsetAndRunsOnBitForBit) {
  // hang2-tear 7 km out: torn (tearing appends copies of particles), untorn with tethers (they
  // are measured between rest positions when the world is planned, so a change in the offsets would
  // show in the steps after loading), torn with tethers (a torn-off copy is tied to its piece's
  // pins as loading ties it), and torn with lines (which put the stretch constraints in line order,
  // and must find the same lines in the loaded order).
  const std::string far = "cloths.0.origin=[-7123.456789,1.5,4987.654321]";
  for (const std::vector<std::string>& overrides :
       {std::vector<std::string>{far, "tearing.threshold=1.03"}, std::vector<std::string>{far, "solver.tethers=true"},
        std::vector<std::string>{far, "tearing.threshold=1.03", "solver.tethers=true"},
        std::vector<std::string>{far, "tearing.threshold=1.03", "solver.stretchSolver=\"lines\""}}) {
    SCOPED_TRACE(overrides[1]);
    const Scene scene = loadScene(resolveScenePath("hang2-tear"), overrides);
    sim::World world(scene.world);
    ASSERT_EQ(world.run(40), sim::StepStatus::ok);
    const sim::ClothRest& rest = world.cloths()[0].rest;
    EXPECT_EQ(rest.particleCount() > 64u * 64u, overrides[1] == "tearing.threshold=1.03");  // torn, or not
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / ("drape-far-" + std::to_string(::getpid()) + ".drape.json");
    writeFileAtomically(file, snapshotDocument(scene, world).dump());
    const Snapshot snapshot = loadSnapshot(file);
    std::filesystem::remove(file);
    ASSERT_EQ(snapshot.cloths.size(), 1u);
    const sim::ClothRest& back = snapshot.cloths[0].rest;
    EXPECT_EQ(back.restOrigin, rest.restOrigin);
    EXPECT_EQ(back.restOffsets, rest.restOffsets);
    sim::World loaded = makeWorld(snapshot);
    for (int step = 0; step < 20; ++step) {
      ASSERT_EQ(world.step(), sim::StepStatus::ok);
      ASSERT_EQ(loaded.step(), sim::StepStatus::ok);
    }
    EXPECT_TRUE(loaded.cloths()[0].state.position == world.cloths()[0].state.position);
    EXPECT_EQ(loaded.cloths()[0].pieceCount, world.cloths()[0].pieceCount);
  }
}

TEST(Snapshot, AWorldWithAMovingColliderGoesOnFromItsClock) {
  // rising-sphere's ball rises through the table and lifts the cloth: loaded, the ball goes on from
  // where the saved world's clock had taken it (made again at time 0, it would start under the table
  // once more and the cloth fall back).
  const Scene scene =
      loadScene(resolveScenePath("rising-sphere"), {"cloths.0.grid.columns=12", "cloths.0.grid.rows=12"});
  sim::World world(scene.world);
  ASSERT_EQ(world.run(60), sim::StepStatus::ok);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-clock-" + std::to_string(::getpid()) + ".drape.json");
  writeFileAtomically(file, snapshotDocument(scene, world).dump());
  sim::World loaded = makeWorld(loadSnapshot(file));
  std::filesystem::remove(file);
  EXPECT_EQ(loaded.stepCount(), world.stepCount());
  ASSERT_EQ(loaded.colliders().size(), world.colliders().size());
  for (int step = 0; step < 60; ++step) {
    ASSERT_EQ(world.step(), sim::StepStatus::ok);
    ASSERT_EQ(loaded.step(), sim::StepStatus::ok);
  }
  EXPECT_TRUE(loaded.cloths()[0].state.position == world.cloths()[0].state.position);
}

TEST(Snapshot, ADrawnFabricClothGoesOnAtItsOwnSubstepsBitForBit) {
  // star's drawn cloth in cotton: its substeps follow the spacing it was drawn at (sim::substepsFor),
  // which its settings in a snapshot no longer hold (the mesh is the snapshot's own). The spacing is
  // kept beside it: loaded, the world runs the same substeps and goes on as the saved one. Without
  // it, the loaded world took the settings' 1 m lattice for the spacing and ran 4 substeps, not 5.
  const Scene scene = withFabric(loadScene(resolveScenePath("star")), "cotton");
  sim::World world(scene.world);
  ASSERT_GT(world.substeps(), scene.world.solver.substeps);
  ASSERT_EQ(world.run(20), sim::StepStatus::ok);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-drawn-" + std::to_string(::getpid()) + ".drape.json");
  writeFileAtomically(file, snapshotDocument(scene, world).dump());
  sim::World loaded = makeWorld(loadSnapshot(file));
  std::filesystem::remove(file);
  EXPECT_EQ(loaded.substeps(), world.substeps());
  EXPECT_EQ(loaded.cloths()[0].spacing, world.cloths()[0].spacing);
  ASSERT_EQ(world.run(20), sim::StepStatus::ok);
  ASSERT_EQ(loaded.run(20), sim::StepStatus::ok);
  EXPECT_TRUE(loaded.cloths()[0].state.position == world.cloths()[0].state.position);
}

TEST(Snapshot, ATetheredClothPinnedAndUnpinnedByHandRunsOnBitForBit) {
  // The tethers go to the cloth's own pins (Cloth::tetherPins), not to one pinned by hand (put
  // anywhere, its rest distances could not all hold); a pin taken out is none any more. A pin
  // made or taken out ties them again, as loading a snapshot ties them: else the loaded world would
  // run on otherwise.
  const Scene scene = loadScene(resolveScenePath("hang2-tear"),
                                {"cloths.0.grid.columns=16", "cloths.0.grid.rows=16", "cloths.0.pins.1.particle=[15,0]",
                                 "solver.tethers=true", "tearing.enabled=false"});
  sim::World world(scene.world);
  const sim::ClothRest& rest = world.cloths()[0].rest;
  const auto at = [&](int column, int row) { return world.cloths()[0].state.position[rest.index(column, row)]; };
  ASSERT_EQ(world.run(10), sim::StepStatus::ok);
  const std::size_t tethers = world.tetherCount();
  // Carry the far corner out and pin it there, then take out the first pin.
  ASSERT_GT(world.pressFinger(1, at(15, 15), 0.01), 0);
  world.moveFinger(1, at(15, 15) + sim::Vec3{0.3, 0.2, 0.0});
  ASSERT_EQ(world.run(10), sim::StepStatus::ok);
  ASSERT_EQ(tethers, 2u * (16u * 16u - 2u));  // every free particle to both corners
  const int pinned = world.pinFinger(1).value();
  ASSERT_GT(pinned, 0);
  EXPECT_EQ(world.tetherCount(), tethers - 2u * static_cast<std::size_t>(pinned));  // none to the new pins
  ASSERT_EQ(world.run(10), sim::StepStatus::ok);
  ASSERT_EQ(world.unpin(at(0, 0), 0.01), 1);
  EXPECT_EQ(world.cloths()[0].tetherPins, std::vector<sim::ParticleIndex>{rest.index(15, 0)});
  EXPECT_EQ(world.tetherCount(), 16u * 16u - 1u - static_cast<std::size_t>(pinned));  // to the one left
  ASSERT_EQ(world.run(5), sim::StepStatus::ok);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-pinned-" + std::to_string(::getpid()) + ".drape.json");
  writeFileAtomically(file, snapshotDocument(scene, world).dump());
  sim::World loaded = makeWorld(loadSnapshot(file));
  std::filesystem::remove(file);
  EXPECT_EQ(loaded.tetherCount(), world.tetherCount());
  EXPECT_EQ(loaded.cloths()[0].tetherPins, world.cloths()[0].tetherPins);
  for (int step = 0; step < 20; ++step) {
    ASSERT_EQ(world.step(), sim::StepStatus::ok);
    ASSERT_EQ(loaded.step(), sim::StepStatus::ok);
  }
  EXPECT_TRUE(loaded.cloths()[0].state.position == world.cloths()[0].state.position);
}

TEST(Snapshot, ASheetWorkingToAStretchTargetRunsOnBitForBitWithItsLinksTension) {
  // hang2 at 32 x 32 working to 4 %: the next step's geometric stiffness reads the tension the last
  // one summed (Cloth::stretchTension), so the snapshot keeps it. Loaded without it, the sheet goes
  // on otherwise: the tension is what makes the two the same.
  const Scene scene = loadScene(resolveScenePath("hang2"), {"cloths.0.grid.columns=32", "cloths.0.grid.rows=32",
                                                            "cloths.0.pins.1.particle=[31,0]"});
  ASSERT_GT(scene.world.solver.maxStretch, 0.0);
  sim::World world(scene.world);
  ASSERT_EQ(world.run(30), sim::StepStatus::ok);
  ASSERT_EQ(world.cloths()[0].stretchTension.size(), world.cloths()[0].rest.of(sim::ConstraintKind::stretch).size());
  const json document = snapshotDocument(scene, world);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-taut-" + std::to_string(::getpid()) + ".drape.json");
  const auto loaded = [&](const json& written) {
    writeFileAtomically(file, written.dump());
    sim::World back = makeWorld(loadSnapshot(file));
    std::filesystem::remove(file);
    return back;
  };
  sim::World with = loaded(document);
  json stripped = document;
  stripped["cloths"][0].erase("stretchTension");
  sim::World without = loaded(stripped);
  EXPECT_EQ(with.cloths()[0].stretchTension, world.cloths()[0].stretchTension);
  for (int step = 0; step < 10; ++step) {
    ASSERT_EQ(world.step(), sim::StepStatus::ok);
    ASSERT_EQ(with.step(), sim::StepStatus::ok);
    ASSERT_EQ(without.step(), sim::StepStatus::ok);
  }
  EXPECT_TRUE(with.cloths()[0].state.position == world.cloths()[0].state.position);
  EXPECT_FALSE(without.cloths()[0].state.position == world.cloths()[0].state.position);
  // One entry per stretch constraint, each a finite number a float holds.
  for (const auto& [bad, what] : {std::pair{json::array({-1.0, 2.0}), "one entry per stretch constraint"},
                                  std::pair{json(), "a finite number of N s^2"}}) {
    json broken = document;
    if (bad.is_null()) {
      broken["cloths"][0]["stretchTension"][3] = 1e39;
    } else {
      broken["cloths"][0]["stretchTension"] = bad;
    }
    writeFileAtomically(file, broken.dump());
    const std::string error = errorOf([&] { loadSnapshot(file); });
    std::filesystem::remove(file);
    EXPECT_NE(error.find("cloths.0.stretchTension"), std::string::npos) << error;
    EXPECT_NE(error.find(what), std::string::npos) << error;
  }
}

TEST(Snapshot, ARestPositionSinglePrecisionCannotHoldIsRefusedByName) {
  const Scene scene = loadScene(resolveScenePath("hang2-tear"),
                                {"cloths.0.grid.columns=4", "cloths.0.grid.rows=4", "cloths.0.pins.1.particle=[3,0]"});
  const sim::World world(scene.world);
  json document = snapshotDocument(scene, world);
  document["cloths"][0]["restPositions"][5][0] = 1e39;
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("drape-wide-" + std::to_string(::getpid()) + ".drape.json");
  writeFileAtomically(file, document.dump());
  const std::string error = errorOf([&] { loadSnapshot(file); });
  std::filesystem::remove(file);
  EXPECT_NE(error.find("cloths.0.restPositions"), std::string::npos) << error;
  EXPECT_NE(error.find("rest position 5"), std::string::npos) << error;
}

}  // namespace
}  // namespace drape::scene
