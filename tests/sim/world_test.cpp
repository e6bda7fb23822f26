// World-level behaviour: the pipeline a scene gets, determinism, and the divergence guard.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <random>
#include <ranges>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"
#include "world_builder.hpp"

namespace drape::sim {
namespace {

std::vector<Stage> stages(const World& world) {
  std::vector<Stage> result;
  for (const StageTiming& timing : world.profile()) result.push_back(timing.stage);
  return result;
}

TEST(Pipeline, HoldsOnlyTheStagesTheSceneUses) {
  WorldSettings settings = test::hangingSheet(8, 10, 1);
  EXPECT_EQ(stages(World(settings)), (std::vector{Stage::verletIntegrate, Stage::projectConstraints, Stage::guard}));

  settings.air.pressure = 1.0;
  settings.air.velocity = Vec3{1.0, 0.0, 0.0};
  settings.cloths[0].material(ConstraintKind::bend).damping = 0.1;
  EXPECT_EQ(stages(World(settings)), (std::vector{Stage::windPressure, Stage::verletIntegrate,
                                                  Stage::projectConstraints, Stage::dampConstraints, Stage::guard}));

  WorldSettings springs = test::verticalSpring(Model::force, Integrator::rk4, 0.01, 100.0, 1.0);
  EXPECT_EQ(stages(World(springs)), (std::vector{Stage::rk4, Stage::guard}));
  springs.solver.integrator = Integrator::symplecticEuler;
  EXPECT_EQ(stages(World(springs)), (std::vector{Stage::symplecticEuler, Stage::guard}));
}

TEST(Pipeline, EveryStageIsTimed) {
  World world(test::hangingSheet(16, 10, 2));
  world.run(5);
  for (const StageTiming& timing : world.profile()) {
    EXPECT_GE(timing.lastSeconds, 0.0);
    EXPECT_GE(timing.totalSeconds, timing.lastSeconds);
  }
  EXPECT_GT(world.profile()[1].totalSeconds, 0.0);  // projecting 1000+ constraints takes some time
}

// The parts of a stage, each timed, in the order they first ran; their times add up to at most the
// stage's (each is timed inside it, and a part inside another, as the tethers between the lines'
// steps, is taken out of the other's).
std::vector<Stage> partsOf(const World& world, Stage stage) {
  std::vector<Stage> result;
  for (const StageTiming& timing : world.profile()) {
    if (timing.stage != stage) continue;
    double sum = 0.0, lastSum = 0.0;
    for (const StageTiming& part : timing.parts) {
      result.push_back(part.stage);
      EXPECT_GT(part.totalSeconds, 0.0) << name(part.stage);
      EXPECT_GE(part.totalSeconds, part.lastSeconds) << name(part.stage);
      EXPECT_TRUE(part.parts.empty()) << name(part.stage);
      sum += part.totalSeconds;
      lastSum += part.lastSeconds;
    }
    EXPECT_LE(sum, timing.totalSeconds * (1.0 + 1e-12)) << name(stage);
    EXPECT_LE(lastSum, timing.lastSeconds * (1.0 + 1e-12)) << name(stage);
  }
  return result;
}

TEST(Pipeline, AStageThatDoesSeveralJobsTimesEachAsItsPart) {
  // The seed's sweep: each kind in turn.
  World seed(test::hangingSheet(16, 4, 2));
  seed.run(3);
  EXPECT_EQ(partsOf(seed, Stage::projectConstraints), (std::vector{Stage::stretch, Stage::shear, Stage::bend}));

  // The fast sweep on a sheet over a plane: the tethers first (and again between the lines' steps,
  // which stretch's time does not count), bend and shear in batches, the lines, the contact planes.
  WorldSettings settings = test::hangingSheet(16, 2, 2);
  settings.solver.stretchSolver = StretchSolver::lines;
  settings.solver.tethers = true;
  settings.solver.maxStretch = 0.04;
  ColliderSettings floor;
  floor.shape = ColliderShape::plane;
  floor.position = Vec3{0.0, 1.0, 0.0};
  floor.normal = Vec3{0.0, 1.0, 0.0};
  settings.colliders.push_back(floor);
  World fast(settings);
  fast.run(20);
  EXPECT_EQ(partsOf(fast, Stage::projectConstraints),
            (std::vector{Stage::tethers, Stage::bend, Stage::shear, Stage::stretch, Stage::contactPlanes}));

  // Self-contact: the broad and narrow phases, the sweeps, the colliders' friction between them and the fail-safe.
  settings.selfCollision.enabled = true;
  World contact(settings);
  contact.run(20);
  EXPECT_EQ(partsOf(contact, Stage::selfContact), (std::vector{Stage::broadPhase, Stage::narrowPhase,
                                                               Stage::contactSweep, Stage::friction, Stage::failSafe}));
  // A stage of one job has none.
  EXPECT_TRUE(partsOf(contact, Stage::verletIntegrate).empty());
}

// The solver's plan (batches, lines) is made when what it is made of changes, never inside a timed
// stage: the constraint stage plans a cloth only as a fallback, and shows it as its part `plan`.
// Every change a world has: made, threads, tuning (the fast sweep switched off and on), a cut,
// tears, a cloth added, restored (an undo) and removed.
TEST(Pipeline, TheSolverIsPlannedWhenTheWorldChangesNotWhileItSteps) {
  WorldSettings settings = test::hangingSheet(16, 2, 2);
  settings.solver.stretchSolver = StretchSolver::lines;
  settings.solver.tethers = true;
  settings.tearing = {true, 1.3};
  World world(settings);
  const auto stepAndCheck = [&](const char* after) {
    world.run(3);
    const std::vector<Stage> parts = partsOf(world, Stage::projectConstraints);
    EXPECT_FALSE(parts.empty()) << after;
    EXPECT_EQ(std::count(parts.begin(), parts.end(), Stage::plan), 0) << after;
  };
  stepAndCheck("made");
  world.setThreads(2);
  stepAndCheck("threads");
  WorldSettings tuned = world.settings();
  tuned.solver.stretchSolver = StretchSolver::gaussSeidel;
  world.tune(tuned);
  stepAndCheck("the seed's sweep");
  tuned.solver.stretchSolver = StretchSolver::lines;
  world.tune(tuned);
  stepAndCheck("the fast sweep");
  const std::vector<Cloth> before = world.cloths().copy();
  const std::uint64_t uncut = world.topologyVersion();
  EXPECT_EQ(world.cut(Vec3{0.0, 2.0, -0.6}, Vec3{0.0, 2.0, 0.6}, Vec3{0.0, -4.0, 0.0}), 1);
  EXPECT_NE(world.topologyVersion(), uncut);
  stepAndCheck("a cut");
  // A corner pulled away by a finger, past the tearing threshold.
  const Vec3 corner = world.cloths()[0].state.position.back();
  ASSERT_GT(world.pressFinger(7, corner, 0.08), 0);
  const std::uint64_t untorn = world.topologyVersion();
  for (int step = 1; step <= 20; ++step) {
    world.moveFinger(7, corner + Vec3{0.0, -0.1, 0.1} * static_cast<Real>(step));
    stepAndCheck("tearing");
  }
  EXPECT_NE(world.topologyVersion(), untorn);
  world.releaseFinger(7);
  world.addCloth(settings.cloths[0]);
  stepAndCheck("a cloth added");
  world.restoreCloths(before);
  stepAndCheck("restored");
  world.addCloth(settings.cloths[0]);
  world.removeCloth(0);
  stepAndCheck("a cloth removed");
}

// Which solver keys go together is said once (sim::conflict); consistent() turns off what does
// not go, and changes nothing that does. Every combination of the keys involved.
TEST(SolverKeys, EveryCombinationIsJudgedOnceAndMadeConsistentByTurningKeysOff) {
  int valid = 0;
  for (int bits = 0; bits < 64; ++bits) {
    SolverSettings s;
    s.model = bits & 1 ? Model::force : Model::position;
    s.integrator = bits & 2 ? Integrator::rk4 : Integrator::verlet;
    s.xpbd = bits & 4;
    s.tethers = bits & 8;
    s.stretchSolver = bits & 16 ? StretchSolver::lines : StretchSolver::gaussSeidel;
    s.maxStretch = bits & 32 ? 0.03 : 0.0;
    const std::optional<SolverConflict> c = conflict(s);
    const bool positionOnly = s.xpbd || s.tethers || s.lines() || s.maxStretch > 0.0;
    const bool goes = (s.model == Model::force ? !positionOnly : s.integrator == Integrator::verlet) &&
                      (s.maxStretch == 0.0 || (s.lines() && !s.xpbd));
    EXPECT_EQ(!c.has_value(), goes) << "combination " << bits;
    const SolverSettings made = consistent(s);
    EXPECT_FALSE(conflict(made).has_value()) << "combination " << bits;
    if (goes) {
      ++valid;
      EXPECT_EQ(made.integrator, s.integrator);
      EXPECT_EQ(made.stretchSolver, s.stretchSolver);
      EXPECT_EQ(made.maxStretch, s.maxStretch);
    }
    // Turning off only: nothing consistent() leaves on was off.
    EXPECT_LE(made.lines(), s.lines());
    EXPECT_LE(made.tethers, s.tethers);
    EXPECT_LE(made.xpbd, s.xpbd);
    EXPECT_LE(made.maxStretch, s.maxStretch);
  }
  EXPECT_GT(valid, 6);
  // The world refuses a combination that does not go, naming the key.
  WorldSettings settings = test::hangingSheet(4, 1, 1);
  settings.solver.maxStretch = 0.04;
  try {
    World world(settings);
    ADD_FAILURE() << "a stretch target without lines was taken";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("solver.maxStretch: 0 unless \"stretchSolver\" is \"lines\"", 0), 0u)
        << error.what();
  }
}

template <typename Settings>
void expectBitIdentical(const Settings& settings, int steps) {
  World a(settings), b(settings);
  a.run(steps);
  b.run(steps);
  const auto& xa = a.cloths()[0].state.position;
  const auto& xb = b.cloths()[0].state.position;
  ASSERT_EQ(xa.size(), xb.size());
  EXPECT_EQ(std::memcmp(xa.data(), xb.data(), xa.size() * sizeof(Vec3)), 0);
}

TEST(Determinism, SameSceneTwiceGivesBitIdenticalPositions) {
  WorldSettings sheet = test::hangingSheet(20, 10, 2);
  sheet.air = {Vec3{0.0, 0.0, 3.0}, 0.1, 0.5};
  expectBitIdentical(sheet, 100);
  WorldSettings springs = test::verticalSpring(Model::force, Integrator::midpoint, 0.001, 1000.0, 0.1);
  expectBitIdentical(springs, 500);
}

TEST(Guard, StopsAtTheFirstNonFiniteStepAndRestoresTheLastGoodState) {
  // A stiff spring under explicit Euler with a large step: |1 + i omega h| = 10 per step.
  World world(test::verticalSpring(Model::force, Integrator::explicitEuler, 0.01, 1.0e6, 1.0));
  const StepStatus status = world.run(10000);
  ASSERT_EQ(status, StepStatus::diverged);
  ASSERT_TRUE(world.divergence().has_value());
  const std::int64_t badStep = world.divergence()->step;
  EXPECT_GT(badStep, 1);
  EXPECT_EQ(world.stepCount(), badStep - 1);  // the bad step did not count
  for (const Vec3& x : world.cloths()[0].state.position) {
    EXPECT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
    EXPECT_LE(std::abs(x.y), kRunawayDistance);
  }
  EXPECT_EQ(world.step(), StepStatus::diverged);  // and it does not step on
  EXPECT_EQ(world.stepCount(), badStep - 1);
}

TEST(Guard, NamesTheFirstParticleThatRunsAwayWhereverItIs) {
  // Free particles (no constraints, no pins) of the position model; one, then two of them given a
  // velocity that takes them past the runaway distance in one step, in different blocks of the
  // guard's scan (blocks of 256) and on either side of one.
  WorldSettings settings = test::hangingSheet(30, 1, 1);
  for (ConstraintKind kind : kConstraintKinds) settings.cloths[0].material(kind) = {0.0, 0.0};
  settings.cloths[0].pins.clear();
  for (const std::vector<ParticleIndex>& runaways :
       std::vector<std::vector<ParticleIndex>>{{700}, {255}, {256}, {899}, {611, 300}, {3, 899}}) {
    World world(settings);
    std::vector<Cloth> cloths = world.cloths().copy();
    ParticleState& s = cloths[0].state;
    for (ParticleIndex i : runaways) s.previousPosition[i] = s.position[i] - Vec3{0.0, 2.0 * kRunawayDistance, 0.0};
    world.restoreCloths(cloths);
    ASSERT_EQ(world.step(), StepStatus::diverged);
    ASSERT_TRUE(world.divergence().has_value());
    EXPECT_EQ(world.divergence()->particle, *std::min_element(runaways.begin(), runaways.end()));
  }
  // And without them it runs.
  World calm(settings);
  EXPECT_EQ(calm.run(10), StepStatus::ok);
}

TEST(Guard, PutsBackEveryPositionAsItWasBeforeTheBadStepBitForBitAtRest) {
  // The position model with its three ways to the positions before the step: one substep leaves
  // them in the previous positions (no copy); the first of three substeps' integration copies
  // them (on a sheet large enough, each of two threads its own part); with a finger down, a copy
  // made before the finger moves anything. The last particle is sent past the runaway distance on
  // the eleventh step; the world must then hold every position it held after the tenth, at rest.
  for (const auto& [n, threads, substeps, finger] : {std::tuple{20, 1, 1, false},
                                                     {20, 1, 1, true},
                                                     {20, 1, 3, false},
                                                     {20, 1, 3, true},
                                                     {100, 2, 1, false},
                                                     {100, 2, 3, false}}) {
    const std::string what = std::to_string(n) + " x " + std::to_string(n) + ", " + std::to_string(threads) +
                             " threads, " + std::to_string(substeps) + " substeps, finger " + std::to_string(finger);
    World world(test::hangingSheet(n, 2, substeps));
    world.setThreads(threads);
    world.run(9);
    if (finger) {
      ASSERT_GT(world.pressFinger(1, world.cloths()[0].state.position[210], 0.08), 0);
      ASSERT_TRUE(world.moveFinger(1, world.cloths()[0].state.position[210] + Vec3{0.0, 0.05, 0.0}));
    }
    ASSERT_EQ(world.step(), StepStatus::ok);
    std::vector<Cloth> cloths = world.cloths().copy();
    cloths[0].state.previousPosition.back() -= Vec3{0.0, 0.0, 1e6 * kRunawayDistance};
    world.restoreCloths(cloths);
    if (finger) {  // another way than before: the finger sets what the particles held were moving at
      ASSERT_GT(world.pressFinger(1, world.cloths()[0].state.position[210], 0.08), 0);
      ASSERT_TRUE(world.moveFinger(1, world.cloths()[0].state.position[210] + Vec3{0.03, 0.0, 0.0}));
    }
    const ParticleState before = world.cloths()[0].state;
    ASSERT_EQ(world.step(), StepStatus::diverged) << what;
    // The guard keeps a copy only where the previous positions will not do.
    EXPECT_EQ(world.memoryUse().guard == 0, substeps == 1 && !finger) << what;
    const ParticleState& after = world.cloths()[0].state;
    EXPECT_EQ(after.position, before.position) << what;
    EXPECT_EQ(after.previousPosition, before.position) << what;
  }
}

TEST(Guard, CopiesWhereAStageAfterIntegrationWritesThePreviousPositions) {
  // One substep, but constraint damping (which changes x_prev) or two cloths with colliders and
  // friction (which do not): the guard copies only for the first, and puts every cloth back.
  WorldSettings damped = test::hangingSheet(20, 2, 1);
  damped.cloths[0].material(ConstraintKind::stretch).damping = 0.2;
  WorldSettings two = test::hangingSheet(20, 2, 1);
  two.cloths.push_back(two.cloths[0]);
  two.cloths[1].lattice.origin += Vec3{2.0, 0.0, 0.0};
  two.colliders.push_back(ColliderSettings{});  // the ground plane
  for (const auto& [settings, copies] : {std::pair{damped, true}, std::pair{two, false}}) {
    World world(settings);
    ASSERT_EQ(world.hasStage(Stage::dampConstraints), copies);
    world.run(10);
    std::vector<Cloth> cloths = world.cloths().copy();
    cloths.back().state.previousPosition.back() -= Vec3{0.0, 0.0, 1e6 * kRunawayDistance};
    world.restoreCloths(cloths);
    const std::vector<Cloth> before = world.cloths().copy();
    ASSERT_EQ(world.step(), StepStatus::diverged);
    EXPECT_EQ(world.memoryUse().guard > 0, copies);
    for (std::size_t c = 0; c < before.size(); ++c) {
      EXPECT_EQ(world.cloths()[c].state.position, before[c].state.position) << "cloth " << c;
      EXPECT_EQ(world.cloths()[c].state.previousPosition, before[c].state.position) << "cloth " << c;
    }
  }
}

TEST(Guard, PutsTheForceModelBackAtRest) {
  // A stiff spring under explicit Euler with a large step (as above): after the bad step, the
  // positions before it with no velocity.
  World world(test::verticalSpring(Model::force, Integrator::explicitEuler, 0.01, 1.0e6, 1.0));
  ParticleState before;
  while (world.stepCount() < 10000) {
    before = world.cloths()[0].state;
    if (world.step() == StepStatus::diverged) break;
  }
  ASSERT_TRUE(world.divergence().has_value());
  const ParticleState& after = world.cloths()[0].state;
  EXPECT_EQ(after.position, before.position);
  EXPECT_EQ(after.previousPosition, before.position);
  ASSERT_EQ(after.velocity.size(), before.velocity.size());
  for (const Vec3& v : after.velocity) EXPECT_EQ(v, Vec3{0.0});
  EXPECT_NE(before.velocity[1], Vec3{0.0});  // it was moving
}

TEST(Guard, AStableRunNeverTrips) {
  World world(test::hangingSheet(16, 10, 2));
  EXPECT_EQ(world.run(300), StepStatus::ok);
  EXPECT_FALSE(world.divergence().has_value());
}

// A cloth's constraints are rest data: kept in one order (orderConstraints), the same whichever
// solver runs, which no plan changes; and the order they are kept in is not physics: the seed's
// sweep takes them by particle pair, so a snapshot with its lists shuffled runs on bit for bit as
// the one kept in order.
TEST(World, KeepsAClothsConstraintsInOneOrderWhicheverSolverRuns) {
  WorldSettings seed = test::hangingSheet(12, 4, 2);
  seed.gravity = Vec3{0.0, -9.81, 0.0};
  WorldSettings lined = seed;
  lined.solver.stretchSolver = StretchSolver::lines;
  World bySeed(seed), byLines(lined);
  const auto made = byLines.cloths()[0].rest.constraints;
  EXPECT_EQ(bySeed.cloths()[0].rest.constraints, made);
  // Planned for lines, on one thread and on two, switched to the seed's sweep and back.
  byLines.run(10);
  EXPECT_EQ(byLines.cloths()[0].rest.constraints, made);
  byLines.setThreads(2);
  byLines.run(5);
  EXPECT_EQ(byLines.cloths()[0].rest.constraints, made);
  WorldSettings next = byLines.settings();
  next.solver.stretchSolver = StretchSolver::gaussSeidel;
  byLines.tune(next);
  byLines.run(5);
  EXPECT_EQ(byLines.cloths()[0].rest.constraints, made);
  next.solver.stretchSolver = StretchSolver::lines;
  byLines.tune(next);
  byLines.run(5);
  EXPECT_EQ(byLines.cloths()[0].rest.constraints, made);

  // The seed's sweep from a snapshot whose lists come in another order, each link either way round:
  // the world keeps them in its order again, and the run is the same to the last bit.
  bySeed.run(10);
  std::vector<Cloth> kept = bySeed.cloths().copy(), shuffled = kept;
  std::mt19937 random(11);
  for (std::vector<DistanceConstraint>& constraints : shuffled[0].rest.constraints) {
    std::shuffle(constraints.begin(), constraints.end(), random);
    for (DistanceConstraint& c : constraints) {
      if (random() % 2) std::swap(c.a, c.b);
    }
  }
  ASSERT_NE(shuffled[0].rest.constraints, made);
  World fromKept(seed), fromShuffled(seed);
  fromKept.restoreCloths(kept);
  fromShuffled.restoreCloths(shuffled);
  EXPECT_EQ(fromShuffled.cloths()[0].rest.constraints, made);
  fromKept.run(30);
  fromShuffled.run(30);
  EXPECT_EQ(fromShuffled.cloths()[0].state.position, fromKept.cloths()[0].state.position);
  EXPECT_NE(fromKept.cloths()[0].state.position, kept[0].state.position);  // it moved
}

// Each cloth is one record (ClothRecord): the cloth and what the world keeps for it alone, the
// held flags among them, go together as cloths come and go. Two sheets, the second held at a corner
// by a finger; the first is removed, and the finger still carries the second's corner (its grip
// moved with it), which a second finger cannot take (its held flag moved with it too: were it left
// behind, the second finger would take the corner as a free particle).
TEST(World, KeepsEachClothWithWhatItHoldsForItAsClothsComeAndGo) {
  WorldSettings settings = test::hangingSheet(6, 10, 2);
  settings.gravity = Vec3{0.0, -9.81, 0.0};
  ClothSettings second = settings.cloths[0];
  second.lattice = {5, 4, 0.4, 0.3, Vec3{2.0, 1.0, 0.0}, LatticePlane::xz};
  second.pins.clear();
  second.fabric = Fabric{};
  settings.cloths.push_back(second);
  World world(settings);

  // The list reads the records, in order; a copy is the cloths as they are.
  const ClothList list = world.cloths();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].state.position.size(), 36u);
  EXPECT_EQ(list[1].state.position.size(), 20u);
  std::size_t particles = 0;
  for (const Cloth& cloth : list) particles += cloth.state.position.size();
  EXPECT_EQ(particles, 56u);
  const auto small = std::ranges::find_if(world.cloths(), [](const Cloth& c) { return c.state.position.size() == 20; });
  EXPECT_EQ(small - list.begin(), 1);
  EXPECT_EQ(&*small, &list.back());
  const std::vector<Cloth> copied = list.copy();
  ASSERT_EQ(copied.size(), 2u);
  EXPECT_EQ(copied[1].state.position, list[1].state.position);

  // Each cloth's settings are its own, as the world uses them; the world's list of them is empty.
  EXPECT_TRUE(world.settings().cloths.empty());
  EXPECT_EQ(list[1].settings.lattice.columns, 5);
  EXPECT_EQ(list[1].settings.material(ConstraintKind::stretch).compliance, 1.0 / Fabric{}.stretchStiffness);

  const Vec3 corner = list[1].state.position[0];
  ASSERT_EQ(world.pressFinger(3, corner, 0.01), 1);
  world.removeCloth(0);
  ASSERT_EQ(world.cloths().size(), 1u);
  EXPECT_EQ(world.finger(3)->grips.front().cloth, 0);
  EXPECT_EQ(world.pressFinger(4, corner, 0.01), 0);
  const Vec3 lifted = corner + Vec3{0.0, 0.2, 0.0};
  world.moveFinger(3, lifted);
  ASSERT_EQ(world.run(30), StepStatus::ok);
  const Cloth& left = world.cloths()[0];
  EXPECT_LT(glm::length(left.state.position[0] - lifted), 1e-9);
  EXPECT_LT(left.state.position[19].y, corner.y - 0.05);  // the far corner, free, fell
}

TEST(World, RejectsSettingsOutsideItsLimits) {
  WorldSettings settings = test::hangingSheet(4, 10, 1);
  settings.solver.dt = 0.0;
  EXPECT_THROW(World{settings}, std::invalid_argument);
  settings = test::hangingSheet(4, 10, 1);
  settings.cloths[0].mass = -1.0;
  EXPECT_THROW(World{settings}, std::invalid_argument);
  settings = test::hangingSheet(4, 10, 1);
  settings.cloths[0].pins.push_back({4, 0, std::nullopt});
  EXPECT_THROW(World{settings}, std::invalid_argument);
  settings = test::hangingSheet(4, 10, 1);
  settings.gravity.y = NAN;
  EXPECT_THROW(World{settings}, std::invalid_argument);
}

TEST(Memory, RestPositionsTakeTwelveBytesAParticle) {
  // Single-precision offsets (ClothRest); the rest count is them and the triangles.
  const World world(test::hangingSheet(20, 2, 1));
  const ClothRest& rest = world.cloths()[0].rest;
  EXPECT_EQ(rest.restOffsets.capacity(), 400u);
  EXPECT_EQ(world.memoryUse().rest, 400u * 12u + rest.triangles.capacity() * sizeof(glm::uvec3));
}

}  // namespace
}  // namespace drape::sim
