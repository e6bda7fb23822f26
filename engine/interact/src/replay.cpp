#include "drape/interact/replay.hpp"

#include <algorithm>
#include <cstdio>
#include <unordered_map>

namespace drape::interact {

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

bool carriesFinger(GestureEvent::Type type) {
  using T = GestureEvent::Type;
  return type == T::down || type == T::move || type == T::up || type == T::pin;
}

}  // namespace

std::string_view name(GestureEvent::Type type) {
  switch (type) {
    case GestureEvent::Type::down: return "down";
    case GestureEvent::Type::move: return "move";
    case GestureEvent::Type::up: return "up";
    case GestureEvent::Type::pin: return "pin";
    case GestureEvent::Type::unpin: return "unpin";
    case GestureEvent::Type::lift: return "lift";
    case GestureEvent::Type::mode: return "mode";
    case GestureEvent::Type::plane: return "plane";
  }
  return "?";
}

double GestureScript::length() const {
  if (duration) return *duration;
  return (events.empty() ? 0.0 : events.back().time) + 1.0;
}

ReplayClock::ReplayClock(const GestureScript& script) : script_(script), following_(script.events.size(), kNone) {
  // One pass from the end: each finger's next event is the last one seen of it.
  std::unordered_map<int, std::size_t> next;
  for (std::size_t i = script.events.size(); i-- > 0;) {
    if (!carriesFinger(script.events[i].type)) continue;
    const auto found = next.find(script.events[i].finger);
    if (found != next.end()) following_[i] = found->second;
    next[script.events[i].finger] = i;
  }
}

std::optional<Pointer> ReplayClock::between(std::size_t from, std::size_t to, double time) const {
  const GestureEvent& a = script_.events[from];
  const GestureEvent& b = script_.events[to];
  if (!a.pointer || !b.pointer || a.pointer->kind != b.pointer->kind) return std::nullopt;
  const double span = b.time - a.time;
  const double f = span > 0.0 ? std::clamp((time - a.time) / span, 0.0, 1.0) : 1.0;
  Pointer p = *a.pointer;
  p.world = a.pointer->world + (b.pointer->world - a.pointer->world) * f;
  p.screen = a.pointer->screen + (b.pointer->screen - a.pointer->screen) * f;
  return p;
}

std::vector<ReplayAction> ReplayClock::advance(double start, double dt) {
  std::vector<ReplayAction> actions;
  while (next_ < script_.events.size() && script_.events[next_].time <= start + 1e-9 * dt) {
    const std::size_t index = next_++;
    const GestureEvent& e = script_.events[index];
    ReplayAction action;
    action.index = index;
    if (e.pointer) action.pointer = *e.pointer;
    actions.push_back(action);
    const auto keyframe =
        std::find_if(keyframe_.begin(), keyframe_.end(), [&](const auto& k) { return k.first == e.finger; });
    if (e.type == GestureEvent::Type::down) {
      if (keyframe == keyframe_.end()) keyframe_.emplace_back(e.finger, index);
    } else if (e.type == GestureEvent::Type::move) {
      if (keyframe != keyframe_.end()) keyframe->second = index;
    } else if (e.type == GestureEvent::Type::up || e.type == GestureEvent::Type::pin) {
      if (keyframe != keyframe_.end()) keyframe_.erase(keyframe);
    }
  }
  // Fingers on their way from one keyframe to the next.
  for (const auto& [finger, from] : keyframe_) {
    const std::size_t to = following_[from];
    if (to == kNone || script_.events[to].type != GestureEvent::Type::move) continue;
    if (const std::optional<Pointer> p = between(from, to, start + dt)) actions.push_back({from, true, *p});
  }
  return actions;
}

Replay::Replay(sim::World& world, Interaction& interaction, const GestureScript& script)
    : world_(world), interaction_(interaction), script_(script), clock_(script), startStep_(world.stepCount()) {
  interaction_.settings() = script.settings;
  if (script.camera) interaction_.setCamera(*script.camera, script.aspect);
}

void Replay::apply(std::size_t index) {
  const GestureEvent& e = script_.events[index];
  bool ok = true;
  switch (e.type) {
    case GestureEvent::Type::down: ok = interaction_.down(e.finger, *e.pointer, e.radius); break;
    case GestureEvent::Type::move: ok = interaction_.move(e.finger, *e.pointer); break;
    case GestureEvent::Type::up: ok = interaction_.up(e.finger); break;
    case GestureEvent::Type::pin: ok = interaction_.pin(e.finger); break;
    case GestureEvent::Type::unpin:
      ok = interaction_.unpin(*e.pointer, e.radius.value_or(interaction_.settings().radius));
      break;
    case GestureEvent::Type::lift: ok = interaction_.lift(e.finger, e.height); break;
    case GestureEvent::Type::mode: interaction_.setMode(e.mode); break;
    case GestureEvent::Type::plane: interaction_.setPlane(e.plane); break;
  }
  if (!ok) {
    char when[64];
    std::snprintf(when, sizeof when, " at %.3f s", e.time);
    reports_.push_back(script_.source + ": event " + std::to_string(index) + " (" + std::string(name(e.type)) + when +
                       "): " + interaction_.lastError() + "; skipped");
  }
}

sim::StepStatus Replay::step() {
  const double dt = world_.settings().solver.dt;
  const double now = static_cast<double>(world_.stepCount() - startStep_) * dt;
  for (const ReplayAction& action : clock_.advance(now, dt)) {
    if (action.onTheWay) {
      interaction_.move(script_.events[action.index].finger, action.pointer);
    } else {
      apply(action.index);
    }
  }
  interaction_.update(dt);
  return world_.step();
}

}  // namespace drape::interact
