// Dynamic resolution (app/render_scale.hpp) against made-up machines: a frame's work is the rest of
// the frame plus a scene that costs a fixed part and a part proportional to its pixels.
#include "render_scale.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace drape::app {
namespace {

struct Machine {
  double others, fixed, perPixel;  // s: the rest of a frame, the scene's fixed part, its part at scale 1
  double scene(double scale) const { return fixed + perPixel * scale * scale; }
  double work(double scale) const { return others + scene(scale); }
};

// The scales over `frames` frames on `machine`.
std::vector<double> run(RenderScale& scale, const Machine& machine, int frames) {
  std::vector<double> scales;
  for (int i = 0; i < frames; ++i) {
    scale.frame(machine.work(scale.scale()), machine.scene(scale.scale()));
    scales.push_back(scale.scale());
  }
  return scales;
}

TEST(RenderScale, AFastMachineKeepsEveryPixel) {
  RenderScale scale;
  const std::vector<double> scales = run(scale, {0.002, 0.001, 0.004}, 400);
  for (double s : scales) EXPECT_EQ(s, 1.0);
}

TEST(RenderScale, ASlowDrawingMachineGoesDownUntilTheFrameFitsAndStaysThere) {
  // The desk on llvmpipe at 1280 x 800 as measured: 6 ms besides the scene, which takes 15 ms, 3 of
  // them whatever its size.
  const Machine desk{0.006, 0.003, 0.012};
  RenderScale scale;
  const std::vector<double> scales = run(scale, desk, 600);
  const double settled = scales.back();
  EXPECT_LT(settled, 1.0);
  EXPECT_LE(desk.work(settled), RenderScale::kBudget);
  // Not lower than it needs: a step up would not fit with the room the rule keeps.
  EXPECT_GT(desk.work(settled + RenderScale::kStep), RenderScale::kRaiseBelow * RenderScale::kBudget);
  // Settled within the first 200 frames and never moved after.
  for (std::size_t i = 200; i < scales.size(); ++i) EXPECT_EQ(scales[i], settled) << i;
}

TEST(RenderScale, ItComesBackUpWhenDrawingGetsCheaperAndStopsAtTheLowestWhenNothingFits) {
  RenderScale scale;
  run(scale, {0.006, 0.003, 0.012}, 300);
  EXPECT_LT(scale.scale(), 1.0);
  run(scale, {0.002, 0.001, 0.004}, 300);  // the cloth went out of view, say
  EXPECT_EQ(scale.scale(), 1.0);
  const std::vector<double> scales = run(scale, {0.030, 0.003, 0.012}, 400);  // the simulation alone is too slow
  EXPECT_EQ(scales.back(), 0.5);
  for (double s : scales) EXPECT_GE(s, 0.5);
}

TEST(RenderScale, OffItStaysWhereSetAndNonsenseFramesAreIgnored) {
  RenderScale scale;
  scale.setAutomatic(false);
  scale.set(0.7);
  run(scale, {0.006, 0.003, 0.012}, 100);
  EXPECT_DOUBLE_EQ(scale.scale(), 0.7);
  scale.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(scale.scale(), 0.5);
  scale.set(3.0);
  EXPECT_EQ(scale.scale(), 1.0);
  scale.setAutomatic(true);
  for (int i = 0; i < 100; ++i) {
    scale.frame(std::numeric_limits<double>::infinity(), 0.01);
    scale.frame(0.05, -1.0);
    scale.frame(std::nan(""), 0.01);
  }
  EXPECT_EQ(scale.scale(), 1.0);
}

}  // namespace
}  // namespace drape::app
