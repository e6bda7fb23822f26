// The renderer in a real off-screen context: what it uploads when, and which way up pictures are.
#include <gtest/gtest.h>

#include "context.hpp"
#include "drape/render/renderer.hpp"
#include "drape/sim/world.hpp"

namespace drape::render {
namespace {

sim::WorldSettings sheet(double height) {
  sim::WorldSettings world;
  sim::ClothSettings cloth;
  cloth.lattice = {8, 8, 1.0, 1.0, sim::Vec3{-0.5, height, -0.5}, sim::LatticePlane::xz};
  cloth.pins = {{0, 0, std::nullopt}, {7, 0, std::nullopt}};
  world.cloths.push_back(cloth);
  return world;
}

constexpr int kWidth = 96, kHeight = 64;

class RendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = cli::OffscreenContext::create(kWidth, kHeight);
    renderer_ = std::make_unique<Renderer>(context_->procAddress());
  }
  std::unique_ptr<cli::OffscreenContext> context_;
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(RendererTest, UploadsIndexBuffersOnlyWhenTheTopologyChanges) {
  sim::World world(sheet(1.0));
  Camera camera;
  for (int frame = 0; frame < 3; ++frame) {
    renderer_->render(world, camera, kWidth, kHeight, {});
    world.step();
  }
  EXPECT_EQ(renderer_->uploadsOfTopology(), 1);  // positions streamed, indices kept
  const sim::World other(sheet(1.0));
  EXPECT_NE(other.topologyVersion(), world.topologyVersion());
  renderer_->render(other, camera, kWidth, kHeight, {});
  EXPECT_EQ(renderer_->uploadsOfTopology(), 2);
}

// Share of saturated (cloth-coloured) pixels in rows [first, last).
double colouredShare(const std::vector<std::uint8_t>& rgba, int first, int last) {
  int coloured = 0;
  for (int y = first; y < last; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::uint8_t* p = &rgba[static_cast<std::size_t>((y * kWidth + x) * 4)];
      const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
      coloured += hi > 40 && (hi - lo) * 100 > hi * 35;
    }
  }
  return static_cast<double>(coloured) / ((last - first) * kWidth);
}

TEST_F(RendererTest, PicturesComeOutTopRowFirst) {
  // A flat sheet high above the camera's target: it must appear in the top half of the picture.
  const sim::World world(sheet(2.0));
  Camera camera;
  camera.target = {0.0, 1.0, 0.0};
  camera.yaw = 0.0;
  camera.pitch = 0.0;
  camera.distance = 3.0;
  renderer_->render(world, camera, kWidth, kHeight, {});
  const std::vector<std::uint8_t> pixels = renderer_->readPixels(kWidth, kHeight);
  EXPECT_GT(colouredShare(pixels, 0, kHeight / 2), 0.02);
  EXPECT_LT(colouredShare(pixels, kHeight / 2, kHeight), 0.005);
}

TEST_F(RendererTest, AMinimisedWindowDrawsNothingAndDoesNotFail) {
  const sim::World world(sheet(1.0));
  renderer_->render(world, Camera{}, 0, 0, {});
  renderer_->render(world, Camera{}, kWidth, kHeight, {});
  EXPECT_EQ(renderer_->uploadsOfTopology(), 1);
}

}  // namespace
}  // namespace drape::render
