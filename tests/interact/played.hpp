// A shipped scene with a shipped gesture script playing on it, stepped as drape-cli replay steps it.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drape/interact/replay.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/intersections.hpp"

namespace drape::test {

inline const std::filesystem::path kAssets = DRAPE_ASSET_DIR;

// A scene with a gesture script playing on it, stepped as drape-cli replay steps it.
struct Played {
  scene::Scene scene;
  std::unique_ptr<sim::World> world;
  interact::GestureScript script;
  std::unique_ptr<interact::Interaction> interaction;
  std::unique_ptr<interact::Replay> replay;

  Played(const std::string& sceneName, const std::string& gestureName)
      : Played(Files{}, kAssets / "scenes" / (sceneName + ".json"), kAssets / "gestures" / (gestureName + ".json")) {}
  // Any scene file with `overrides` (as drape-cli's --set), and any script; an empty script path
  // plays none (the scene runs on its own, for the script's duration if given to until()).
  struct Files {};
  Played(Files, const std::filesystem::path& sceneFile, const std::filesystem::path& gestureFile,
         const std::vector<std::string>& overrides = {})
      : scene(scene::loadScene(sceneFile, overrides)),
        world(std::make_unique<sim::World>(scene.world)),
        script(gestureFile.empty() ? interact::GestureScript{} : scene::loadGesture(gestureFile)),
        interaction(std::make_unique<interact::Interaction>(*world)),
        replay(std::make_unique<interact::Replay>(*world, *interaction, script)) {
    interaction->settings().material = scene::drawnClothTemplate(scene);
  }

  // Intersecting triangle pairs (intersections.hpp), counted every kCountEvery steps as it plays:
  // the most at any of them, and at which step.
  static constexpr std::int64_t kCountEvery = 5;
  std::size_t worstIntersections = 0;
  std::int64_t worstStep = 0;

  // Plays until `seconds` of simulated time (the script's length if not given).
  void until(double seconds = -1.0) {
    if (seconds < 0.0) seconds = script.length();
    while (world->time() < seconds - 1e-9) {
      ASSERT_EQ(replay->step(), sim::StepStatus::ok);
      if (world->stepCount() % kCountEvery != 0) continue;
      const std::size_t pairs = sim::countIntersections(*world).pairs;
      if (pairs > worstIntersections) {
        worstIntersections = pairs;
        worstStep = world->stepCount();
      }
    }
    EXPECT_TRUE(replay->reports().empty()) << replay->reports().front();
  }
  const sim::Cloth& cloth(int index = 0) const { return world->cloths().at(static_cast<std::size_t>(index)); }
};

// Measures of a cloth as it lies.
inline sim::Vec3 centroid(const sim::Cloth& cloth) {
  sim::Vec3 sum{0.0};
  for (const sim::Vec3& x : cloth.state.position) sum += x;
  return sum / static_cast<sim::Real>(cloth.state.position.size());
}

inline sim::Real highest(const sim::Cloth& cloth) {
  sim::Real y = -1e9;
  for (const sim::Vec3& x : cloth.state.position) y = std::max(y, x.y);
  return y;
}

inline sim::Real lowest(const sim::Cloth& cloth) {
  sim::Real y = 1e9;
  for (const sim::Vec3& x : cloth.state.position) y = std::min(y, x.y);
  return y;
}

// Root mean square distance of the particles from their middle, across the table (x-z).
inline sim::Real spread(const sim::Cloth& cloth) {
  const sim::Vec3 middle = centroid(cloth);
  sim::Real sum = 0.0;
  for (const sim::Vec3& x : cloth.state.position)
    sum += (x.x - middle.x) * (x.x - middle.x) + (x.z - middle.z) * (x.z - middle.z);
  return std::sqrt(sum / static_cast<sim::Real>(cloth.state.position.size()));
}

}  // namespace drape::test
