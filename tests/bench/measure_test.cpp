// The benchmark's own arithmetic: the median it reports, and that its two solvers measure the
// same scene the same way.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "drape/bench/hang2.hpp"
#include "drape/bench/measure.hpp"
#include "drape/scene/scene.hpp"

namespace drape::bench {
namespace {

TEST(Median, IsTheMiddleOrTheMeanOfTheTwoMiddles) {
  EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);  // not the upper middle, 3
  EXPECT_DOUBLE_EQ(median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(median({})));
}

// One hang2: what the benchmark and the tests run is the shipped scene file, at the size asked,
// with only the solver keys a case sets changed.
TEST(Hang2, IsTheShippedSceneFileAtTheSizeAsked) {
  const sim::WorldSettings file = scene::loadScene(std::string(DRAPE_ASSET_DIR) + "/scenes/hang2.json").world;
  const sim::WorldSettings built = hang2(128);
  EXPECT_EQ(built.solver.dt, file.solver.dt);
  EXPECT_EQ(built.solver.substeps, file.solver.substeps);
  EXPECT_EQ(built.solver.iterations, file.solver.iterations);
  EXPECT_EQ(built.solver.stretchSolver, file.solver.stretchSolver);
  EXPECT_EQ(built.solver.tethers, file.solver.tethers);
  EXPECT_EQ(built.solver.maxStretch, file.solver.maxStretch);
  EXPECT_EQ(built.gravity, file.gravity);
  ASSERT_EQ(built.cloths.size(), 1u);
  ASSERT_EQ(file.cloths.size(), 1u);
  const sim::ClothSettings &a = built.cloths[0], &b = file.cloths[0];
  EXPECT_EQ(a.lattice.columns, b.lattice.columns);
  EXPECT_EQ(a.lattice.rows, b.lattice.rows);
  EXPECT_EQ(a.lattice.width, b.lattice.width);
  EXPECT_EQ(a.lattice.origin, b.lattice.origin);
  EXPECT_EQ(a.mass, b.mass);
  for (const sim::ConstraintKind kind : sim::kConstraintKinds) {
    EXPECT_EQ(a.material(kind).stiffness, b.material(kind).stiffness);
    EXPECT_EQ(a.material(kind).damping, b.material(kind).damping);
  }
  ASSERT_EQ(a.pins.size(), b.pins.size());
  for (std::size_t p = 0; p < a.pins.size(); ++p) {
    EXPECT_EQ(a.pins[p].column, b.pins[p].column);
    EXPECT_EQ(a.pins[p].row, b.pins[p].row);
  }
  // Another size pins its own corners; a case's solver key changes that key alone.
  Hang2Solver three;
  three.substeps = 3;
  const sim::WorldSettings small = hang2(16, three);
  EXPECT_EQ(small.cloths[0].lattice.columns, 16);
  EXPECT_EQ(small.cloths[0].pins[1].column, 15);
  EXPECT_EQ(small.solver.substeps, 3);
  EXPECT_EQ(small.solver.maxStretch, file.solver.maxStretch);
  EXPECT_THROW(hang2(1), std::invalid_argument);
}

TEST(Measure, DrapeAndTheNaiveLoopMeasureTheSameSheet) {
  // hang2 at 16 x 16 for 30 frames: both count the same particles, and Drape's sweep ends far
  // tauter than ten naive Gauss-Seidel sweeps.
  const sim::WorldSettings world = hang2(16);
  const Measurement drape = measureWorld(world, 30, 1, 1);
  const Measurement naive = measureNaive(world, 30, 10, 1);
  EXPECT_EQ(drape.particles, 256u);
  EXPECT_EQ(naive.particles, 256u);
  EXPECT_FALSE(drape.diverged);
  EXPECT_LT(drape.strainMaxRun, 0.05);
  EXPECT_GT(naive.strainMaxRun, 2.0 * drape.strainMaxRun);
  EXPECT_GE(drape.strainMaxRun, drape.strainMaxEnd);
  EXPECT_GT(drape.msPerFrame, 0.0);
}

}  // namespace
}  // namespace drape::bench
