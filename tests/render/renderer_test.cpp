// The renderer in a real off-screen context: what it uploads when, which way up pictures are, and
// what the views (table, weave, wireframe, particles) put on the picture.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/quaternion.hpp>

#include "collider_geometry.hpp"
#include "context.hpp"
#include "drape/render/layer.hpp"
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

// A camera looking straight down at the sheet's middle from 2 m.
Camera fromAbove(double height) {
  Camera camera;
  camera.target = {0.0, height, 0.0};
  camera.yaw = 0.0;
  camera.pitch = 1.5;
  camera.distance = 2.0;
  return camera;
}

// A rounded box is drawn on its own surface, or the inset inside it: every point of the drawing at
// the collider's signed distance -inset, facing the way the surface there does, and its triangles
// (each corner one of its points) covering the surface's area, that of the inner box (the half
// extents less the radius, all less the inset) grown by the radius: its faces, a quarter cylinder
// along each edge and an eighth of a sphere at each corner, less what the chords of 11.25 degrees
// cut off (0.6 % where the radius is the smallest half extent; a face missing would take 10 %). Turned, moved, and
// rounded by a radius more and less than the inset, by the smallest half extent (the inner box flat), and by 1e-17 m
// (drawn sharp).
TEST(ColliderGeometry, ARoundedBoxIsDrawnOnItsSurface) {
  const double pi = 3.141592653589793;
  for (const double rounding : {0.0, 1e-17, 0.001, 0.05, 0.35}) {
    for (const double inset : {0.0, 0.002}) {
      SCOPED_TRACE(::testing::Message() << "rounding " << rounding << ", inset " << inset);
      sim::ColliderSettings s;
      s.shape = sim::ColliderShape::box;
      s.position = {0.3, 0.4, -0.2};
      s.orientation = glm::angleAxis(0.7, glm::normalize(sim::Vec3{1.0, 2.0, 0.5}));
      s.halfExtents = {0.5, 0.35, 0.4};
      s.rounding = rounding;
      const sim::Collider box(s);
      ColliderGeometry geometry;
      appendColliderGeometry(box, geometry, inset);
      ASSERT_FALSE(geometry.indices.empty());
      ASSERT_EQ(geometry.indices.size() % 3, 0u);
      double farthest = 0.0, turned = 0.0;
      for (std::size_t i = 0; i < geometry.positions.size(); ++i) {
        const sim::SurfaceDistance d = box.distance(sim::Vec3(geometry.positions[i]), 1.0);
        ASSERT_TRUE(std::isfinite(d.distance)) << i;
        farthest = std::max(farthest, std::abs(d.distance + inset));
        turned = std::max(turned, glm::length(sim::Vec3(geometry.normals[i]) - d.normal));
      }
      EXPECT_LT(farthest, 1e-6);
      // (A sharp box's edge points face one of their faces; the distance's normal there is the
      // other's or either: only the rounded ones are checked for it. The drawing's points are
      // floats, some 3e-8 m off, which turns the normal of a 1 mm round by some 3e-5.)
      if (rounding > inset + 1e-9) {
        EXPECT_LT(turned, 1e-4);
      }
      double area = 0.0;
      for (std::size_t k = 0; k < geometry.indices.size(); k += 3) {
        for (int j = 0; j < 3; ++j) ASSERT_LT(geometry.indices[k + j], geometry.positions.size());
        const sim::Vec3 a(geometry.positions[geometry.indices[k]]), b(geometry.positions[geometry.indices[k + 1]]),
            c(geometry.positions[geometry.indices[k + 2]]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
      }
      const double r = std::max(rounding - inset, 0.0);
      const sim::Vec3 inner = s.halfExtents - sim::Vec3{inset} - sim::Vec3{r};
      const double expected = 8.0 * (inner.x * inner.y + inner.y * inner.z + inner.z * inner.x) +
                              4.0 * pi * r * (inner.x + inner.y + inner.z) + 4.0 * pi * r * r;
      EXPECT_LT(area, expected * (1.0 + 1e-6));
      EXPECT_GT(area, expected * (1.0 - 1e-2));
    }
  }
}

TEST_F(RendererTest, TheTableIsDrawnOnlyWhereTheWorldHasOne) {
  // Looking along the horizon from above a sheet: the lower half of the picture is where a floor
  // would be. Without a table it shows the background's colour and nothing else.
  sim::WorldSettings settings = sheet(3.0);
  Camera camera;
  camera.target = {0.0, 3.0, 0.0};
  camera.pitch = 0.3;
  camera.distance = 4.0;
  FrameOptions options;
  const auto background = [&](const std::vector<std::uint8_t>& rgba) {
    int same = 0;
    for (int y = kHeight * 3 / 4; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const std::uint8_t* p = &rgba[static_cast<std::size_t>((y * kWidth + x) * 4)];
        same += std::abs(p[0] - std::lround(options.backgroundColour.r * 255.0f)) <= 1 &&
                std::abs(p[1] - std::lround(options.backgroundColour.g * 255.0f)) <= 1 &&
                std::abs(p[2] - std::lround(options.backgroundColour.b * 255.0f)) <= 1;
      }
    }
    return static_cast<double>(same) / (kWidth * kHeight / 4);
  };
  const sim::World floating(settings);
  renderer_->render(floating, camera, kWidth, kHeight, options);
  EXPECT_GT(background(renderer_->readPixels(kWidth, kHeight)), 0.99);
  settings.colliders.push_back(sim::ColliderSettings{});  // a plane through the origin, facing up
  const sim::World onTable(settings);
  renderer_->render(onTable, camera, kWidth, kHeight, options);
  EXPECT_LT(background(renderer_->readPixels(kWidth, kHeight)), 0.05);
}

// Mean and spread of the brightness of the pixels in the middle quarter of the picture.
void brightness(const std::vector<std::uint8_t>& rgba, double& mean, double& spread, int& dark, int& white) {
  double sum = 0.0, squares = 0.0;
  int n = 0;
  dark = 0;
  white = 0;
  for (int y = kHeight * 3 / 8; y < kHeight * 5 / 8; ++y) {
    for (int x = kWidth * 3 / 8; x < kWidth * 5 / 8; ++x) {
      const std::uint8_t* p = &rgba[static_cast<std::size_t>((y * kWidth + x) * 4)];
      const double v = (p[0] + p[1] + p[2]) / 3.0;
      sum += v;
      squares += v * v;
      dark += v < 50.0;
      white += std::min({p[0], p[1], p[2]}) > 225;
      ++n;
    }
  }
  mean = sum / n;
  spread = std::sqrt(std::max(squares / n - mean * mean, 0.0));
}

TEST_F(RendererTest, TheWeavePrintsAChecksAndTheWireframeAndParticlesDrawOverTheSurface) {
  // A 1 m sheet seen from above fills the middle of the picture: plain, it is one colour; woven,
  // its 5 cm checks make bands of white and colour; its edges (wireframe) and particles add dark
  // lines and white dots.
  const sim::World world(sheet(1.0));
  const Camera camera = fromAbove(1.0);
  double mean = 0.0, spread = 0.0;
  int dark = 0, white = 0;
  FrameOptions plain;
  plain.woven = false;
  renderer_->render(world, camera, kWidth, kHeight, plain);
  brightness(renderer_->readPixels(kWidth, kHeight), mean, spread, dark, white);
  const double plainSpread = spread, plainMean = mean;
  EXPECT_EQ(dark, 0);
  EXPECT_EQ(white, 0);
  FrameOptions woven;
  renderer_->render(world, camera, kWidth, kHeight, woven);
  brightness(renderer_->readPixels(kWidth, kHeight), mean, spread, dark, white);
  EXPECT_GT(spread, plainSpread + 10.0);
  EXPECT_GT(mean, plainMean);  // the white threads
  FrameOptions wireframe = plain;
  wireframe.wireframe = true;
  renderer_->render(world, camera, kWidth, kHeight, wireframe);
  brightness(renderer_->readPixels(kWidth, kHeight), mean, spread, dark, white);
  const int wires = dark;
  EXPECT_GT(wires, 20);  // an 8 x 8 sheet's edges cross the middle
  FrameOptions particles = plain;
  particles.particles = true;
  renderer_->render(world, camera, kWidth, kHeight, particles);
  brightness(renderer_->readPixels(kWidth, kHeight), mean, spread, dark, white);
  EXPECT_GT(white, 0);  // the dots
}

// Pixels that are neither the background nor the cloth's flat colour: the blends antialiasing
// makes along the cloth's edges.
int blended(const std::vector<std::uint8_t>& rgba, const FrameOptions& options) {
  const glm::vec3 background = options.backgroundColour * 255.0f;
  int count = 0;
  for (std::size_t i = 0; i < rgba.size(); i += 4) {
    const glm::vec3 c(rgba[i], rgba[i + 1], rgba[i + 2]);
    const bool isBackground = glm::length(c - background) < 6.0f;
    const bool isCloth = c.r > 150.0f && c.r > 1.8f * c.b;  // the orange front, lit
    count += !isBackground && !isCloth;
  }
  return count;
}

TEST_F(RendererTest, FxaaBlendsTheClothsEdgesAsMultisamplingDoes) {
  // A sheet turned 30 degrees, seen from above with no table and no pins, off the picture's middle
  // (FXAA filters only the rectangle the cloth covers: a rectangle turned upside down would miss
  // it): without antialiasing its edges are stairs of pure cloth and pure background; FXAA and
  // MSAA put blends between.
  sim::WorldSettings settings = sheet(1.0);
  settings.cloths[0].pins.clear();
  const sim::World world(settings);
  Camera camera = fromAbove(1.0);
  camera.yaw = 0.52;
  camera.distance = 3.2;
  camera.pan(0.12, -0.12);
  FrameOptions options;
  options.woven = false;
  options.showPins = false;
  options.multisample = false;
  options.fxaa = false;
  renderer_->render(world, camera, kWidth, kHeight, options);
  const int aliased = blended(renderer_->readPixels(kWidth, kHeight), options);
  options.fxaa = true;
  renderer_->render(world, camera, kWidth, kHeight, options);
  const int filtered = blended(renderer_->readPixels(kWidth, kHeight), options);
  options.fxaa = false;
  options.multisample = true;
  renderer_->render(world, camera, kWidth, kHeight, options);
  const int multisampled = blended(renderer_->readPixels(kWidth, kHeight), options);
  EXPECT_LT(aliased, 5);
  EXPECT_GT(filtered, 40);  // the sheet's four edges cross some 200 pixel rows and columns
  EXPECT_GT(multisampled, 40);
  std::printf("blended pixels: none %d, FXAA %d, MSAA %d\n", aliased, filtered, multisampled);
}

TEST_F(RendererTest, FxaaFiltersEachFrameFromThatFramesPicture) {
  // FXAA copies the part of the picture it filters into a texture of its own; drawn after another
  // frame (the table's shadow map bound in between), the picture is the one a renderer that drew
  // nothing before makes: the copy lands in FXAA's texture, not in the shadow map.
  sim::WorldSettings settings = sheet(0.3);
  settings.colliders.push_back(sim::ColliderSettings{});  // the table, with the sheet's shadow on it
  const sim::World world(settings);
  Camera before = fromAbove(1.0);
  before.yaw = 0.52;
  Camera camera = before;
  camera.pitch = 0.6;
  camera.pan(0.12, -0.12);
  FrameOptions options;
  options.multisample = false;
  options.fxaa = true;
  renderer_->render(world, before, kWidth, kHeight, options);
  renderer_->render(world, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> second = renderer_->readPixels(kWidth, kHeight);
  Renderer fresh(context_->procAddress());
  fresh.render(world, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> first = fresh.readPixels(kWidth, kHeight);
  ASSERT_EQ(second.size(), first.size());
  int differing = 0;
  for (std::size_t i = 0; i < first.size(); ++i) differing += first[i] != second[i];
  EXPECT_EQ(differing, 0);
  EXPECT_GT(blended(second, options), 40);  // and it was filtered
}

TEST_F(RendererTest, AWireframeAtHalfScaleLaysAboutAsMuchInkAsAtFullScale) {
  // Drawn at half the pixels and scaled up, each line is two of the window's pixels wide: unfaded,
  // a wireframe darkened the picture about twice as much as at full scale (the app's desk went near
  // black). Ink: how much darker than the same picture without the wireframe, summed.
  sim::WorldSettings settings = sheet(1.0);
  settings.cloths[0].lattice.columns = settings.cloths[0].lattice.rows = 12;
  settings.cloths[0].pins = {{0, 0, std::nullopt}, {11, 0, std::nullopt}};
  const sim::World world(settings);
  Camera camera = fromAbove(1.0);
  camera.distance = 2.0;
  FrameOptions options;
  options.woven = false;
  options.multisample = false;
  options.fxaa = false;
  const auto ink = [&](float scale) {
    options.renderScale = scale;
    options.wireframe = false;
    renderer_->render(world, camera, kWidth, kHeight, options);
    const std::vector<std::uint8_t> bare = renderer_->readPixels(kWidth, kHeight);
    options.wireframe = true;
    renderer_->render(world, camera, kWidth, kHeight, options);
    const std::vector<std::uint8_t> wired = renderer_->readPixels(kWidth, kHeight);
    double sum = 0.0;
    for (std::size_t i = 0; i < bare.size(); i += 4) {
      for (int c = 0; c < 3; ++c) sum += std::max(0, static_cast<int>(bare[i + c]) - static_cast<int>(wired[i + c]));
    }
    return sum;
  };
  const double full = ink(1.0f), half = ink(0.5f);
  ASSERT_GT(full, 0.0);
  // Faded by the scale: 0.89 of the full picture's ink; unfaded, 1.46.
  EXPECT_NEAR(half / full, 1.0, 0.25) << "full " << full << ", half " << half;
}

TEST_F(RendererTest, AtHalfScaleTheSceneIsDrawnSmallerAndStretchedOverTheSamePixels) {
  // The same sheet at render scale 1 and 0.5 covers the same part of the picture (to its stretched
  // edges); the half-scale picture is not the full one (it was drawn at a quarter of the pixels
  // and filtered up), and a scale that is not a number draws at the lowest scale, not at none.
  const sim::World world(sheet(1.0));
  Camera camera = fromAbove(1.0);
  camera.yaw = 0.52;
  camera.distance = 3.2;
  FrameOptions options;
  options.woven = false;
  options.multisample = false;
  const auto cloth = [](const std::vector<std::uint8_t>& rgba) {
    int count = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) count += rgba[i] > 150 && rgba[i] > 1.8 * rgba[i + 2];
    return count;
  };
  renderer_->render(world, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> full = renderer_->readPixels(kWidth, kHeight);
  options.renderScale = 0.5f;
  renderer_->render(world, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> half = renderer_->readPixels(kWidth, kHeight);
  options.renderScale = std::numeric_limits<float>::quiet_NaN();
  renderer_->render(world, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> unnamed = renderer_->readPixels(kWidth, kHeight);
  EXPECT_GT(cloth(full), 600);
  EXPECT_NEAR(cloth(half), cloth(full), 0.1 * cloth(full));
  EXPECT_NE(half, full);
  EXPECT_EQ(unnamed, half);
}

TEST_F(RendererTest, TheHiddenStripIsLeftToTheBackgroundAndTheRestIsAsBefore) {
  // A panel will cover the right third: the scene (table, sheet and its shadow) is drawn as before
  // left of it, pixel for pixel, and only the background colour is under it; at half scale too.
  // Next to the strip, FXAA (6 pixels, 12 at half scale) and the stretch's filter see it.
  sim::WorldSettings settings = sheet(0.3);
  settings.colliders.push_back(sim::ColliderSettings{});
  const sim::World world(settings);
  Camera camera = fromAbove(1.0);
  camera.pitch = 0.6;
  FrameOptions options;
  options.multisample = false;
  constexpr int kHidden = kWidth / 3;
  for (const float scale : {1.0f, 0.5f}) {
    options.renderScale = scale;
    options.hiddenRight = 0;
    renderer_->render(world, camera, kWidth, kHeight, options);
    const std::vector<std::uint8_t> whole = renderer_->readPixels(kWidth, kHeight);
    options.hiddenRight = kHidden;
    renderer_->render(world, camera, kWidth, kHeight, options);
    const std::vector<std::uint8_t> hidden = renderer_->readPixels(kWidth, kHeight);
    const glm::vec3 background = options.backgroundColour * 255.0f;
    int changedLeft = 0, sceneRight = 0, differentRight = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const std::size_t i = static_cast<std::size_t>((y * kWidth + x) * 4);
        const glm::vec3 c(hidden[i], hidden[i + 1], hidden[i + 2]);
        if (x < kWidth - kHidden - 14) {
          changedLeft += hidden[i] != whole[i] || hidden[i + 1] != whole[i + 1] || hidden[i + 2] != whole[i + 2];
        } else if (x >= kWidth - kHidden) {
          sceneRight += glm::length(c - background) > 1.5f;
          differentRight += hidden[i] != whole[i];
        }
      }
    }
    EXPECT_EQ(changedLeft, 0) << "scale " << scale;
    EXPECT_EQ(sceneRight, 0) << "scale " << scale;
    EXPECT_GT(differentRight, kHidden * kHeight / 2) << "scale " << scale;  // the table was there
  }
}

TEST_F(RendererTest, ALayerKeepsItsPictureAndCopiesARectangleOfItToTheSamePlace) {
  // A sheet drawn into a layer; then the picture bound now shows a scene without it (the table
  // and sky only) and the layer's left half is copied over it: left half the sheet's picture, the
  // right half untouched, and the layer still holds it for the key it was drawn with.
  sim::WorldSettings settings = sheet(0.3);
  settings.colliders.push_back(sim::ColliderSettings{});
  const sim::World withSheet(settings);
  settings.cloths.clear();
  const sim::World without(settings);
  const Camera camera = fromAbove(1.0);
  FrameOptions options;
  options.multisample = false;
  renderer_->render(withSheet, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> sheetPicture = renderer_->readPixels(kWidth, kHeight);
  renderer_->render(without, camera, kWidth, kHeight, options);
  const std::vector<std::uint8_t> emptyPicture = renderer_->readPixels(kWidth, kHeight);
  ASSERT_NE(sheetPicture, emptyPicture);

  Layer layer;
  EXPECT_FALSE(layer.holds(7, kWidth, kHeight));
  ASSERT_TRUE(layer.begin(7, kWidth, kHeight));
  renderer_->render(withSheet, camera, kWidth, kHeight, options);
  layer.end();
  EXPECT_TRUE(layer.holds(7, kWidth, kHeight));
  EXPECT_FALSE(layer.holds(8, kWidth, kHeight));
  EXPECT_FALSE(layer.holds(7, kWidth + 1, kHeight));
  renderer_->render(without, camera, kWidth, kHeight, options);  // into the picture bound before begin
  layer.copyTo(0, 0, kWidth / 2, kHeight);
  const std::vector<std::uint8_t> copied = renderer_->readPixels(kWidth, kHeight);
  int wrongLeft = 0, wrongRight = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = static_cast<std::size_t>((y * kWidth + x) * 4);
      const std::vector<std::uint8_t>& expected = x < kWidth / 2 ? sheetPicture : emptyPicture;
      const bool same =
          copied[i] == expected[i] && copied[i + 1] == expected[i + 1] && copied[i + 2] == expected[i + 2];
      (x < kWidth / 2 ? wrongLeft : wrongRight) += !same;
    }
  }
  EXPECT_EQ(wrongLeft, 0);
  EXPECT_EQ(wrongRight, 0);
  layer.invalidate();
  EXPECT_FALSE(layer.holds(7, kWidth, kHeight));
}

}  // namespace
}  // namespace drape::render
