// Determinism as a contract a user can check (as Box2D's test_determinism.c keeps it): every
// shipped scene, and every shipped gesture on its scene, stepped on 1, 2 and 4 threads, must end in
// the same state bit for bit on each, and in the state recorded in determinism.txt. A change that
// moves any of them fails here until the file is regenerated, on purpose, by
//   tools/determinism
// (which runs this test with DRAPE_UPDATE_DETERMINISM set to the file to write).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "drape/sim/metrics.hpp"
#include "played.hpp"

namespace drape::test {
namespace {

constexpr int kSceneSteps = 12;    // every shipped scene, alone (0.2 s at 60 Hz)
constexpr int kGestureSteps = 60;  // every gesture's first second (at 60 Hz), fingers at work
constexpr int kThreadCounts[] = {1, 2, 4};

struct Case {
  std::string name;     // "scene hang", "gesture desk/crumple"
  std::string scene;    // a shipped scene
  std::string gesture;  // and the gesture played on it, or ""
};

std::vector<Case> cases() {
  std::vector<Case> all;
  std::vector<std::string> scenes;
  for (const auto& entry : std::filesystem::directory_iterator(kAssets / "scenes")) {
    if (entry.path().extension() == ".json") scenes.push_back(entry.path().stem().string());
  }
  std::sort(scenes.begin(), scenes.end());
  for (const std::string& scene : scenes) all.push_back({"scene " + scene, scene, ""});
  // Each gesture on the scene its test in gesture_test.cpp plays it on.
  const std::map<std::string, std::string> sceneOf = {
      {"drape", "desk-ball"}, {"tear", "desk-tear"}, {"draw", "empty-table"}};
  std::vector<std::string> gestures;
  for (const auto& entry : std::filesystem::directory_iterator(kAssets / "gestures")) {
    if (entry.path().extension() == ".json") gestures.push_back(entry.path().stem().string());
  }
  std::sort(gestures.begin(), gestures.end());
  for (const std::string& gesture : gestures) {
    const auto found = sceneOf.find(gesture);
    const std::string scene = found == sceneOf.end() ? "desk" : found->second;
    all.push_back({"gesture " + scene + "/" + gesture, scene, gesture});
  }
  return all;
}

std::uint64_t finalState(const Case& c, int threads) {
  if (c.gesture.empty()) {
    sim::World world(scene::loadScene(kAssets / "scenes" / (c.scene + ".json")).world);
    world.setThreads(threads);
    EXPECT_EQ(world.run(kSceneSteps), sim::StepStatus::ok) << c.name;
    return sim::stateHash(world);
  }
  Played played(c.scene, c.gesture);
  played.world->setThreads(threads);
  for (int i = 0; i < kGestureSteps; ++i) EXPECT_EQ(played.replay->step(), sim::StepStatus::ok) << c.name;
  return sim::stateHash(*played.world);
}

std::string hex(std::uint64_t hash) {
  std::ostringstream text;
  text << std::hex << hash;
  return text.str();
}

const std::filesystem::path kRecord = std::filesystem::path(DRAPE_SOURCE_DIR) / "tests/interact/determinism.txt";

TEST(Determinism, EveryShippedSceneAndGestureEndsInTheRecordedStateOnEveryThreadCount) {
  std::map<std::string, std::string> recorded;
  {
    std::ifstream in(kRecord);
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      const std::size_t space = line.rfind(' ');
      recorded[line.substr(0, space)] = line.substr(space + 1);
    }
  }
  std::ostringstream record;
  record << "# The final state of every shipped scene (" << kSceneSteps << " steps) and gesture (" << kGestureSteps
         << " steps) as an FNV-1a hash of every position and previous position, the same on 1, 2 and 4 threads.\n"
         << "# Checked by tests/interact/determinism_test.cpp; regenerate with tools/determinism.\n";
  for (const Case& c : cases()) {
    std::uint64_t first = 0;
    for (const int threads : kThreadCounts) {
      const std::uint64_t hash = finalState(c, threads);
      if (threads == kThreadCounts[0]) first = hash;
      EXPECT_EQ(hex(hash), hex(first)) << c.name << " on " << threads << " threads differs from 1 thread";
    }
    record << c.name << ' ' << hex(first) << '\n';
    if (!std::getenv("DRAPE_UPDATE_DETERMINISM")) {
      EXPECT_EQ(hex(first), recorded[c.name])
          << c.name << ": the final state moved (or is new). If that is meant, regenerate " << kRecord
          << " with tools/determinism and say why in the commit.";
    }
  }
  if (std::getenv("DRAPE_UPDATE_DETERMINISM")) {
    std::ofstream(kRecord) << record.str();
    GTEST_SKIP() << "wrote " << kRecord;
  }
}

}  // namespace
}  // namespace drape::test
