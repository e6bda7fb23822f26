// Gesture scripts: a timeline of finger events, replayed against a world step by step. The same
// events the app's input layer produces, so a script drives the headless engine and the app alike.
//
// Timing: an event at time T takes effect before the first step that starts at or after T. Between
// a finger's down and its moves, and from one move to the next, the pointer travels in a straight
// line (in the coordinates the events give), so two events make a smooth drag; two events with the
// same time make a jump.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drape/interact/interaction.hpp"

namespace drape::interact {

struct GestureEvent {
  enum class Type : std::uint8_t { down, move, up, pin, unpin, lift, mode, plane };
  double time = 0.0;  // s
  Type type = Type::move;
  int finger = 0;
  std::optional<Pointer> pointer;  // down, move, unpin
  std::optional<Real> radius;      // down (m), unpin (m)
  Real height = 0.0;               // lift (m)
  Mode mode = Mode::sticky;        // mode
  FingerPlane plane = FingerPlane::table;  // plane
};

std::string_view name(GestureEvent::Type type);

struct GestureScript {
  std::string source;  // where it came from, for messages
  std::optional<render::Camera> camera;
  double aspect = 4.0 / 3.0;
  std::optional<double> duration;  // s, how long a replay runs (default: the last event + 1 s)
  InteractionSettings settings;
  std::vector<GestureEvent> events;  // in time order

  double length() const;
};

class Replay {
 public:
  // The interaction's camera and settings are set from the script.
  Replay(sim::World& world, Interaction& interaction, const GestureScript& script);

  // Applies what is due, then steps the world once.
  sim::StepStatus step();
  bool finished() const { return next_ >= script_.events.size(); }
  // Events that could not be honoured: "gesture.json: event 4 (up at 1.20 s): finger 2 is not down; skipped".
  const std::vector<std::string>& reports() const { return reports_; }

 private:
  void apply(std::size_t index);
  std::optional<Pointer> between(std::size_t from, std::size_t to, double time) const;

  sim::World& world_;
  Interaction& interaction_;
  const GestureScript& script_;
  std::size_t next_ = 0;
  // Per event: the index of the same finger's next down/move/up/pin event, or npos.
  std::vector<std::size_t> following_;
  // Per finger down: the last keyframe applied.
  std::vector<std::pair<int, std::size_t>> keyframe_;
  std::vector<std::string> reports_;
};

}  // namespace drape::interact
