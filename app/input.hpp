// The app's input layer: touch and mouse events in, fingers and camera moves out.
//
// Events are the app's own (sdl_events.cpp translates SDL's one to one), so this layer is a pure
// function of the events and the camera and is tested without a window. Bindings (docs/app.md):
//   touch          every touch is a sticky finger (or draws, or cuts, in those modes); many at once
//   left drag      a finger; with Shift held at the press it stays down when the button is released
//   Ctrl + left    lifts the parked (Shift) finger whose ring is nearest the pointer
//   wheel          lifts the finger being dragged, or the last parked one, by a twentieth of the
//                  camera's distance a notch; with none, zooms; over a panel, scrolls it
//   right drag     orbits the camera; middle drag pans it
// A press over a panel (the UI wants the mouse) goes to the panel, not the cloth.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drape/interact/interaction.hpp"
#include "drape/render/camera.hpp"

namespace drape::app {

struct InputEvent {
  enum class Kind : std::uint8_t { touchDown, touchMove, touchUp, mouseDown, mouseMove, mouseUp, wheel, focusLost };
  Kind kind = Kind::mouseMove;
  std::int64_t touch = 0;   // the touch device
  std::int64_t finger = 0;  // the touch on it (SDL reuses these ids once a touch ends)
  double x = 0.0, y = 0.0;  // normalised to the window: 0..1 from the top left, not clamped
  int button = 0;           // 1 left, 2 middle, 3 right
  bool shift = false;
  bool ctrl = false;
  double wheel = 0.0;  // notches, positive away from the user
  // A replayed script's touch at a world point (m): the finger goes there as drape-cli replay
  // puts it, not through the screen and back onto the finger's plane, which would lose a point's
  // height above the table. Real touches have none.
  std::optional<interact::Vec3> world;
  std::optional<double> radius;  // a replayed down's own finger radius (m), as the script gave it
};

struct InputOptions {
  double wheelLift = 0.05;      // camera distances a wheel notch lifts a finger ...
  double wheelLiftMin = 0.005;  // ... but no less than this (m) ...
  double wheelLiftMax = 0.25;   // ... nor more (m)
  double orbitSpeed = 4.0;      // rad per window width dragged
  double zoomPerNotch = 1.1;    // distance divided by this per notch towards the scene
  double parkedReach = 0.05;    // a Ctrl-click lifts a parked finger whose ring is this close (window heights)
};

// A window's rectangle in normalised window coordinates (0..1 from the top left).
struct ScreenRect {
  double left = 0.0, top = 0.0, right = 0.0, bottom = 0.0;
  bool contains(double x, double y) const { return x >= left && x < right && y >= top && y < bottom; }
};

// Whether a pointer at (x, y) is over one of the panels' windows. The app asks this of the windows
// as they were drawn last frame, for each event as it comes: not Dear ImGui's WantCaptureMouse, which
// is decided once a frame and would send a click just after the pointer moved onto a panel (or off
// it) the wrong way.
inline bool overAny(const std::vector<ScreenRect>& rects, double x, double y) {
  for (const ScreenRect& r : rects) {
    if (r.contains(x, y)) return true;
  }
  return false;
}

class InputMapper {
 public:
  InputMapper(interact::Interaction& interaction, render::Camera& camera, InputOptions options = {});

  void handle(const InputEvent& event, bool uiWantsMouse);

  int touchesDown() const { return static_cast<int>(touchIds_.size()); }
  // The engine finger a touch is, while it is down.
  std::optional<int> touchFinger(std::int64_t touch, std::int64_t finger) const {
    const auto found = touchIds_.find({touch, finger});
    return found == touchIds_.end() ? std::nullopt : std::optional<int>(found->second);
  }
  int parkedFingers() const { return static_cast<int>(parked_.size()); }
  bool parked(int id) const;    // a Shift-parked mouse finger
  double liftPerNotch() const;  // m a wheel notch lifts, now
  bool dragging() const { return drag_ != Drag::none; }
  // How many times a finger was moved or lifted (touch, mouse or wheel) so far: while the world is
  // paused, the app steps it once for each frame in which this grew, so the cloth follows the hand.
  std::int64_t fingerMoves() const { return fingerMoves_; }
  // Events that could not be honoured (an up for a touch that is not down), newest last.
  const std::vector<std::string>& problems() const { return problems_; }

  // The engine ids fingers get: touches count up from 1, mouse fingers from kMouseIds.
  static constexpr int kMouseIds = 1 << 24;

 private:
  enum class Drag : std::uint8_t { none, finger, orbit, pan };
  struct Parked {
    int id;
    double height;
  };

  void report(std::string problem);
  void forgetLifted();
  void liftBy(int id, double& height, double notches);

  interact::Interaction& interaction_;
  render::Camera& camera_;
  InputOptions options_;
  std::map<std::pair<std::int64_t, std::int64_t>, int> touchIds_;
  int nextTouchId_ = 1;
  int nextMouseId_ = kMouseIds;
  Drag drag_ = Drag::none;
  int dragFinger_ = 0;
  bool parkOnRelease_ = false;
  double dragHeight_ = 0.0;
  double lastX_ = 0.0, lastY_ = 0.0;
  std::vector<Parked> parked_;
  std::vector<std::string> problems_;
  std::int64_t fingerMoves_ = 0;
};

}  // namespace drape::app
