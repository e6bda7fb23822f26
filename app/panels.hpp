// The Dear ImGui panels, the HUD and the help overlay, and what keys do. No SDL here.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "drape/render/renderer.hpp"
#include "input.hpp"
#include "render_scale.hpp"
#include "session.hpp"

struct ImDrawList;

namespace drape::app {

enum class KeyAction : std::uint8_t {
  none,
  pause,
  step,
  reset,
  undo,
  redo,
  screenshot,
  sticky,
  cut,
  create,
  plane,
  help,
  panels,
  save,
  load,
  frame,      // F: the cloths fill the view
  resetView,  // Home: the camera as the scene starts
  edges,      // W: the triangles' edges on or off
  strain,     // C: strain colours on or off
  askQuit,    // Esc: quits when pressed twice
  quit
};

// A fixed-length history for the plots.
class History {
 public:
  static constexpr int kLength = 240;
  void add(float value);
  const float* data() const { return values_.data(); }
  int offset() const { return next_; }
  float latest() const { return values_[static_cast<std::size_t>((next_ + kLength - 1) % kLength)]; }
  float largest() const;

 private:
  std::array<float, kLength> values_{};
  int next_ = 0;
};

struct FrameStats {
  double simulationSeconds = 0.0;  // wall time of the last frame's steps
  int steps = 0;
  bool fellBehind = false;
  double drawSeconds = 0.0;
  double sceneSeconds = 0.0, panelSeconds = 0.0, swapSeconds = 0.0;  // parts of drawing
  double frameSeconds = 1.0 / 60.0;
  History fps, stepMilliseconds, drawMilliseconds;

  void simulation(double seconds, int stepsTaken, bool behind);
  void drawing(double seconds, double frame);
};

struct PanelState {
  // The panels' windows as they were last drawn, in normalised window coordinates: an event over
  // one goes to the panels (overAny), decided for each event as it comes.
  std::vector<ScreenRect> windows;
  float panelWidth = 0.0f;  // points, of the main panel as last drawn (0 when hidden)
  // Points at the window's right edge the main panel (opaque) hid as last drawn: from its left edge
  // to the window's, while it stands against that edge top to bottom; 0 otherwise. The scene is not
  // drawn there (FrameOptions::hiddenRight).
  float hiddenRight = 0.0f;
  // The main panel's draw list and rectangle (points: x, y from the top left, width, height) as
  // last drawn, while it is open and opaque (null otherwise): the app keeps its picture in a layer
  // and draws it again only when the list changed.
  const ImDrawList* panelDrawList = nullptr;
  float panelRect[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  float lastDisplayWidth = -1.0f, lastDisplayHeight = -1.0f;  // the panel is placed again when these change
  bool collapsedBySize = false;  // the panel was collapsed because the window was too small
  bool showHelp = false;
  bool closePopups = false;  // Esc was pressed with a list open: close it in the next frame
  bool showPanels = true;
  bool wantScreenshot = false;
  std::string file = "drape-save.drape.json";  // save and load
  // The snapshot the session was opened from that `file` was last set to: a snapshot opened (from
  // the command line, or loaded) becomes the file that Ctrl+S writes and Ctrl+O reads.
  std::filesystem::path fileFrom;
  // Software GL (llvmpipe) pays for every sample and shadow tap: the app starts light (measured at
  // 1280 x 800 on 2 cores: 4x MSAA cost 35 ms a frame, a 2048^2 shadow map 10 ms more than 1024^2;
  // FXAA over the cloth about as much as filtering the shadows with 9 taps instead of 1, so the
  // app antialiases with FXAA and filters its shadows by the hardware's 2 x 2 comparison alone).
  render::FrameOptions frameOptions = [] {
    render::FrameOptions options;
    options.multisample = false;
    options.fxaa = true;
    options.shadowSoftness = 0;
    options.shadowMapSize = 1024;
    return options;
  }();
  // The fraction of the window's width and height the scene is drawn at: chosen from the frames'
  // cost to keep 60 fps unless set by hand (View panel, --render-scale).
  RenderScale renderScale;
  History maxStrain, meanStrain, energy;
  // Intersecting triangle pairs (sim/intersections.hpp), counted every kIntersectionFrames frames:
  // a count costs about a pass over the triangles, too much to take every frame on a fine cloth.
  static constexpr int kIntersectionFrames = 10;
  int framesSinceCount = kIntersectionFrames;
  std::size_t intersections = 0;
  History intersectionHistory;
  std::vector<History> stages;  // per stage of the world's pipeline and per part of one, ms per frame
  std::vector<std::string> stageNames;
};

// Applies a key's action to the session (pause, reset, undo, modes, ...).
void applyKey(KeyAction action, Session& session, PanelState& panels);

// Draws the panels, the HUD and the help; returns a file to load when the user picked one.
std::optional<std::filesystem::path> drawPanels(Session& session, PanelState& panels, FrameStats& stats,
                                                const InputMapper& input);

// Rings for sticky fingers (a parked one in cyan, a pinched one in yellow; a lifted one with a line
// down to its plane), paths for cuts and outlines being drawn.
render::Overlay fingerOverlay(Session& session, const InputMapper& input);

// The outline a create finger is drawing, as the cloth it would make: width and depth (m) and about
// how many particles at `spacing` (the mesher's count: cells plus half the perimeter in spacings).
struct OutlineSize {
  double width = 0.0, depth = 0.0;
  double particles = 0.0;
};
OutlineSize outlineSize(const std::vector<glm::dvec3>& stroke, double spacing);

}  // namespace drape::app
