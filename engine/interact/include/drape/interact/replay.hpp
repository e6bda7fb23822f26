// Gesture scripts: a timeline of finger events, replayed against a world step by step. The same
// events the app's input layer produces, so a script drives the headless engine and the app alike.
//
// Timing: an event at time T takes effect before the first step that starts at or after T. Between
// a finger's down and its moves, and from one move to the next, the pointer travels in a straight
// line (in the coordinates the events give), so two events make a smooth drag; two events with the
// same time make a jump.
#pragma once

#include <cstdint>

#include <optional>
#include <string>
#include <vector>

#include "drape/interact/interaction.hpp"

namespace drape::interact {

struct GestureScript {
  std::string source;  // where it came from, for messages
  std::optional<render::Camera> camera;
  double aspect = 4.0 / 3.0;
  std::optional<double> duration;  // s, how long a replay runs (default: the last event + 1 s)
  InteractionSettings settings;
  std::vector<GestureEvent> events;  // in time order

  double length() const;
};

// One thing due before a step: an event of the script, or a finger's move on its way from one
// keyframe to the next.
struct ReplayAction {
  std::size_t index = 0;  // the script's event (for a move on the way: the finger's last keyframe)
  bool onTheWay = false;
  Pointer pointer;  // on the way: where the finger is at the end of the step
};

// The timeline of a script without its effects: what is due when. The replay below applies the
// actions to an Interaction; the app turns them into touch events pushed through SDL.
class ReplayClock {
 public:
  explicit ReplayClock(const GestureScript& script);
  std::vector<ReplayAction> advance(double start, double dt);
  bool finished() const { return next_ >= script_.events.size(); }

 private:
  std::optional<Pointer> between(std::size_t from, std::size_t to, double time) const;

  const GestureScript& script_;
  std::size_t next_ = 0;
  // Per event: the index of the same finger's next down/move/up/pin event, or npos.
  std::vector<std::size_t> following_;
  // Per finger down: its last keyframe.
  std::vector<std::pair<int, std::size_t>> keyframe_;
};

class Replay {
 public:
  // The interaction's camera and settings are set from the script.
  Replay(sim::World& world, Interaction& interaction, const GestureScript& script);

  // Applies what is due, then steps the world once.
  sim::StepStatus step();
  bool finished() const { return clock_.finished(); }
  // Events that could not be honoured: "gesture.json: event 4 (up at 1.20 s): finger 2 is not down; skipped".
  const std::vector<std::string>& reports() const { return reports_; }

 private:
  void apply(std::size_t index);

  sim::World& world_;
  Interaction& interaction_;
  const GestureScript& script_;
  ReplayClock clock_;
  // The world's step when the replay began: the script's times count from there (a world loaded
  // from a snapshot starts where it was saved).
  std::int64_t startStep_;
  std::vector<std::string> reports_;
};

}  // namespace drape::interact
