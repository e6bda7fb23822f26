// The desktop app: an SDL2 window with a GL 3.3 core context, the engine at a fixed step, the
// renderer, and Dear ImGui panels on top. docs/app.md lists what it does and how to drive it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace drape::app {

// Exit codes, as drape-cli's: 0 ok, 1 the simulation diverged (only with --exit-after), 2 bad input,
// 3 internal error; and 4: no display (or no GL 3.3 context on it).
inline constexpr int kExitNoDisplay = 4;

struct AppOptions {
  std::string scene = "desk";         // a scene (path or shipped name) or a snapshot (*.drape.json)
  std::optional<std::string> replay;  // gesture script, pushed through SDL as touch events
  std::optional<std::string> record;  // write what the fingers did here at exit
  // After frame N (from 1), write the window to this PNG; any number, in any order.
  std::vector<std::pair<std::int64_t, std::string>> screenshots;
  std::optional<std::int64_t> exitAfter;  // frames
  std::optional<std::string> out;         // final state (JSON) at exit, as drape-cli run --out
  int width = 1280;
  int height = 800;
  std::optional<int> threads;  // simulation threads; by default every core (at most 8)
  std::optional<double>
      renderScale;       // the scene's fraction of the window's size, fixed; by default chosen to keep 60 fps
  bool timings = false;  // at exit, print the median cost of a frame's parts to stdout
};

int runApp(const AppOptions& options);

}  // namespace drape::app
