// The hand's side of Drape: finger events in, engine calls out.
//
// A finger event carries a pointer, either a point in the world or a point of the picture seen
// through the camera. What a finger does depends on the mode it went down in (after Toh 2011):
//   sticky  it sticks to the cloth under it and carries it; two holding fingers that come within
//           `pinchDistance` of each other lift what they hold by `pinchHeight` (pinch-lift);
//   cut     its path cuts the cloth (the swipe, extended along the view direction, or straight down
//           for world pointers);
//   create  its path is an outline; when it lifts, a cloth of that shape appears on the table.
// A screen pointer moves in the finger's plane: the table plane (horizontal) or the view plane
// (facing the camera), through the point where the finger went down; towards the horizon it goes
// no farther than three camera distances from the plane's point under the eye. World pointers are
// taken as they are. A finger's height above its plane is set by `lift` (the mouse wheel, say).
//
// Events that cannot be honoured (an unknown finger, a second down for one id, a pointer that is
// not finite) are skipped and explained in lastError(); they never throw.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

#include "drape/render/camera.hpp"
#include "drape/sim/world.hpp"

namespace drape::interact {

using sim::Real;
using sim::Vec3;

enum class Mode : std::uint8_t { sticky, cut, create };
enum class FingerPlane : std::uint8_t { table, view };
std::string_view name(Mode mode);
std::string_view name(FingerPlane plane);
std::optional<Mode> parseMode(std::string_view text);
std::optional<FingerPlane> parsePlane(std::string_view text);

struct Pointer {
  enum class Kind : std::uint8_t { world, screen };
  Kind kind = Kind::world;
  Vec3 world{0.0};         // m
  glm::dvec2 screen{0.0};  // the picture's x, y in 0..1 from the top left (may lie outside)

  static Pointer at(Vec3 point) { return {Kind::world, point, {}}; }
  static Pointer onScreen(double x, double y) { return {Kind::screen, Vec3{0.0}, {x, y}}; }
};

struct InteractionSettings {
  Real radius = 0.05;  // m, of a sticky finger
  FingerPlane plane = FingerPlane::table;
  Real pinchDistance = 0.1;  // m: two holding fingers closer than this pinch-lift
  Real pinchHeight = 0.2;    // m, how far a pinch lifts
  Real liftSpeed = 1.0;      // m/s, how fast a finger rises or sinks to a new height (pinch, lift)
  // Drawn cloths:
  Real spacing = 0.02;          // m, between particles (the desk cloth's, 32 x 32 over 60 cm: 1.9 cm)
  Real tableHeight = 0.0;       // m, the table's y (outlines are drawn on it)
  Real clothHeight = 0.01;      // m, above the table where a drawn cloth appears
  Real arealDensity = 0.2;      // kg/m^2
  sim::ClothSettings material;  // materials and thickness of drawn cloths
};

// One event of a finger's life, as gesture scripts hold them and the app records them.
struct GestureEvent {
  enum class Type : std::uint8_t { down, move, up, pin, unpin, lift, mode, plane };
  double time = 0.0;  // s
  Type type = Type::move;
  int finger = 0;
  std::optional<Pointer> pointer;          // down, move, unpin
  std::optional<Real> radius;              // down (m), unpin (m)
  Real height = 0.0;                       // lift (m)
  Mode mode = Mode::sticky;                // mode
  FingerPlane plane = FingerPlane::table;  // plane
};

std::string_view name(GestureEvent::Type type);

// What the overlay shows of a finger.
struct TouchView {
  int id;
  Mode mode;
  Vec3 position;             // m, where it is (including lifts)
  Vec3 base;                 // m, where it is in its plane (without them)
  std::vector<Vec3> stroke;  // create and cut: the path so far
  bool holds;                // sticky: it holds particles
  bool pinched;              // sticky: it is pinch-lifted
};

class Interaction {
 public:
  explicit Interaction(sim::World& world, InteractionSettings settings = {});

  void setCamera(const render::Camera& camera, double aspect);
  const render::Camera& camera() const { return camera_; }
  double aspect() const { return aspect_; }
  void setMode(Mode mode);
  Mode mode() const { return mode_; }
  void setPlane(FingerPlane plane);
  InteractionSettings& settings() { return settings_; }
  const InteractionSettings& settings() const { return settings_; }

  // `radius` overrides the settings' radius for this finger.
  bool down(int id, const Pointer& pointer, std::optional<Real> radius = std::nullopt);
  bool move(int id, const Pointer& pointer);
  bool up(int id);
  bool pin(int id);  // a sticky finger lifts and leaves what it holds pinned
  bool lift(int id, Real height);
  bool unpin(const Pointer& pointer, Real radius);
  // Lifts every finger (losing focus, say): sticky fingers let go, strokes are dropped.
  void cancelAll();
  // Before each world step of `dt` seconds: pinch-lift, and each sticky finger's target.
  void update(Real dt);
  // Removes the most recently drawn cloth still in the world. False if there is none.
  bool undoSpawn();

  // Called once per cut stroke, before it first cuts, so the app can take a snapshot to undo it;
  // and when the stroke ends having cut nothing, so the snapshot can be dropped.
  std::function<void()> beforeCut;
  std::function<void()> cutNothing;
  // Called when a cut stroke that cut something lifts, with its path (m, on the table or the view
  // plane): the app shows it as a seam for a moment.
  std::function<void(const std::vector<Vec3>&)> afterCut;
  // Called when a drawn cloth has been added to the world.
  std::function<void()> afterSpawn;
  // Called with a line worth showing the user when a drawn outline lifts: the cloth it made (its
  // particles and size, and whether a crossing stroke kept only its largest loop), or why none.
  std::function<void(const std::string&)> tell;
  // Called after every event that took, with world pointers (where the finger went down, moved,
  // drew or cut), so a session can be recorded as a gesture script; the time is the caller's.
  std::function<void(const GestureEvent&)> record;

  const std::string& lastError() const { return lastError_; }
  std::vector<TouchView> touches() const;
  int spawnedCount() const { return static_cast<int>(spawnedIndex_.size()); }
  // The world's index of the most recently drawn cloth still in it (what undoSpawn would take).
  std::optional<int> lastSpawned() const {
    return spawnedIndex_.empty() ? std::nullopt : std::optional<int>(spawnedIndex_.back());
  }
  // Records the cloth at `index` as the most recently drawn one (a drawn cloth put back by a redo).
  void noteSpawned(int index) { spawnedIndex_.push_back(index); }

 private:
  struct Touch {
    int id = 0;
    Mode mode = Mode::sticky;
    Vec3 anchor{0.0};            // a point of the finger's plane
    Vec3 normal{0.0, 1.0, 0.0};  // the plane's normal
    Vec3 onPlane{0.0};           // where the pointer is, in the plane (or in the world)
    Real height = 0.0;           // m, lifted by the user ...
    Real heightGoal = 0.0;       // ... on its way here at liftSpeed
    Real pinch = 0.0;            // m, lifted by a pinch
    bool holds = false;
    std::vector<Vec3> stroke;
    Vec3 depth{0.0, -1.0, 0.0};  // cut: the direction the cut surface extends along
    bool cutStarted = false;     // beforeCut was called for this stroke
    bool cutSomething = false;
  };

  bool fail(std::string message);
  void note(GestureEvent::Type type, int id, std::optional<Vec3> at = std::nullopt);
  Touch* find(int id);
  std::optional<Vec3> pointOnPlane(const Pointer& pointer, Vec3 anchor, Vec3 normal) const;
  bool spawn(const Touch& touch);

  sim::World& world_;
  InteractionSettings settings_;
  render::Camera camera_;
  double aspect_ = 4.0 / 3.0;
  Mode mode_ = Mode::sticky;
  std::vector<Touch> touches_;
  std::vector<int> spawnedIndex_;  // cloths drawn, in order
  std::string lastError_;
};

}  // namespace drape::interact
