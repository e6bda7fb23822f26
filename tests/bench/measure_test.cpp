// The benchmark's own arithmetic: the median it reports, and that its two solvers measure the
// same scene the same way.
#include <gtest/gtest.h>

#include <cmath>

#include "drape/bench/hang2.hpp"
#include "drape/bench/measure.hpp"

namespace drape::bench {
namespace {

TEST(Median, IsTheMiddleOrTheMeanOfTheTwoMiddles) {
  EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);  // not the upper middle, 3
  EXPECT_DOUBLE_EQ(median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(median({})));
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
