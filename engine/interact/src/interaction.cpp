#include "drape/interact/interaction.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "drape/mesh/outline.hpp"

namespace drape::interact {

namespace {

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

const Vec3 kUp{0.0, 1.0, 0.0};

// A screen pointer's finger stays within this many camera distances of the point of its plane
// under the eye.
constexpr Real kReach = 3.0;

// Area of the loop in the table plane (x, z).
Real loopArea(const std::vector<glm::dvec2>& loop) {
  Real twice = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const glm::dvec2 a = loop[i], b = loop[(i + 1) % loop.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return std::abs(twice) / 2.0;
}

}  // namespace

std::string_view name(Mode mode) {
  switch (mode) {
    case Mode::sticky: return "sticky";
    case Mode::cut: return "cut";
    case Mode::create: return "create";
  }
  return "?";
}

std::string_view name(FingerPlane plane) { return plane == FingerPlane::table ? "table" : "view"; }

std::optional<Mode> parseMode(std::string_view text) {
  for (Mode mode : {Mode::sticky, Mode::cut, Mode::create}) {
    if (text == name(mode)) return mode;
  }
  return std::nullopt;
}

std::optional<FingerPlane> parsePlane(std::string_view text) {
  for (FingerPlane plane : {FingerPlane::table, FingerPlane::view}) {
    if (text == name(plane)) return plane;
  }
  return std::nullopt;
}

Interaction::Interaction(sim::World& world, InteractionSettings settings)
    : world_(world), settings_(std::move(settings)) {}

void Interaction::setCamera(const render::Camera& camera, double aspect) {
  camera_ = camera;
  aspect_ = aspect > 0.0 && std::isfinite(aspect) ? aspect : 1.0;
}

void Interaction::setMode(Mode mode) {
  mode_ = mode;
  if (!record) return;
  GestureEvent e;
  e.type = GestureEvent::Type::mode;
  e.mode = mode;
  record(e);
}

void Interaction::setPlane(FingerPlane plane) {
  settings_.plane = plane;
  if (!record) return;
  GestureEvent e;
  e.type = GestureEvent::Type::plane;
  e.plane = plane;
  record(e);
}

void Interaction::note(GestureEvent::Type type, int id, std::optional<Vec3> at) {
  if (!record) return;
  GestureEvent e;
  e.type = type;
  e.finger = id;
  if (at) e.pointer = Pointer::at(*at);
  record(e);
}

bool Interaction::fail(std::string message) {
  lastError_ = std::move(message);
  return false;
}

Interaction::Touch* Interaction::find(int id) {
  for (Touch& touch : touches_) {
    if (touch.id == id) return &touch;
  }
  return nullptr;
}

std::optional<Vec3> Interaction::pointOnPlane(const Pointer& pointer, Vec3 anchor, Vec3 normal) const {
  if (pointer.kind == Pointer::Kind::world) {
    if (!finite(pointer.world)) return std::nullopt;
    return pointer.world;
  }
  if (!std::isfinite(pointer.screen.x) || !std::isfinite(pointer.screen.y)) return std::nullopt;
  const render::Ray ray = camera_.ray(pointer.screen.x, pointer.screen.y, aspect_);
  // The plane's point under the eye, and the ray's heading within the plane.
  const Vec3 foot = ray.origin - normal * glm::dot(ray.origin - anchor, normal);
  const Vec3 heading = ray.direction - normal * glm::dot(ray.direction, normal);
  const Real reach = kReach * camera_.distance;
  const Real facing = glm::dot(ray.direction, normal);
  if (std::abs(facing) > 1e-9) {
    const Real t = glm::dot(anchor - ray.origin, normal) / facing;
    const Vec3 hit = ray.origin + ray.direction * t;
    if (t > 0.0 && glm::length(hit - foot) <= reach) return hit;
  }
  // Towards the horizon (or above it) a small move of the pointer would carry the finger metres, or
  // to no point at all: the finger goes no farther than `reach` from the foot, in the ray's heading.
  if (!(glm::length(heading) > 1e-9)) return std::nullopt;  // straight at the plane along its normal
  return foot + glm::normalize(heading) * reach;
}

bool Interaction::down(int id, const Pointer& pointer, std::optional<Real> radius) {
  if (find(id)) return fail("finger " + std::to_string(id) + " is already down");
  if (touches_.size() >= static_cast<std::size_t>(sim::kMaxFingers)) {
    return fail("finger " + std::to_string(id) + ": " + std::to_string(sim::kMaxFingers) +
                " fingers are down already, the most there can be");
  }
  const Real r = radius.value_or(settings_.radius);
  if (!(r > 0.0) || !std::isfinite(r)) return fail("finger radius must be a positive number");
  Touch touch;
  touch.id = id;
  touch.mode = mode_;
  const Vec3 tableAnchor{0.0, settings_.tableHeight, 0.0};
  const Vec3 viewNormal = -camera_.forward();

  if (mode_ == Mode::sticky) {
    std::optional<Vec3> pressed;
    if (pointer.kind == Pointer::Kind::world) {
      if (!finite(pointer.world)) return fail("finger " + std::to_string(id) + ": the point is not finite");
      if (!world_.pressFinger(id, pointer.world, r)) return fail("finger " + std::to_string(id) + " is already down");
      pressed = pointer.world;
    } else {
      if (!std::isfinite(pointer.screen.x) || !std::isfinite(pointer.screen.y)) {
        return fail("finger " + std::to_string(id) + ": the screen point is not finite");
      }
      const render::Ray ray = camera_.ray(pointer.screen.x, pointer.screen.y, aspect_);
      pressed = world_.pressFingerAlongRay(id, ray.origin, ray.direction, r);
    }
    touch.holds = pressed.has_value();
    touch.normal = settings_.plane == FingerPlane::table ? kUp : viewNormal;
    touch.anchor = pressed ? *pressed : tableAnchor;
    if (!pressed) {
      // Nothing under the finger: it is down, on the table plane, holding nothing.
      touch.normal = kUp;
      const std::optional<Vec3> onTable = pointOnPlane(pointer, tableAnchor, kUp);
      touch.anchor = onTable.value_or(tableAnchor);
    }
    touch.onPlane = touch.anchor;
  } else {
    // Cut and create strokes are drawn on the table; a cut extends along the view direction.
    const std::optional<Vec3> onTable = pointOnPlane(pointer, tableAnchor, kUp);
    if (!onTable) return fail("finger " + std::to_string(id) + ": the point is not on the table");
    touch.anchor = touch.onPlane = *onTable;
    touch.stroke.push_back(*onTable);
    touch.depth = pointer.kind == Pointer::Kind::screen ? camera_.forward() : -kUp;
  }
  if (record) {
    GestureEvent e;
    e.type = GestureEvent::Type::down;
    e.finger = id;
    e.pointer = Pointer::at(touch.onPlane);
    if (radius) e.radius = r;
    record(e);
  }
  touches_.push_back(std::move(touch));
  return true;
}

bool Interaction::move(int id, const Pointer& pointer) {
  Touch* touch = find(id);
  if (!touch) return fail("finger " + std::to_string(id) + " is not down");
  const std::optional<Vec3> point = pointOnPlane(pointer, touch->anchor, touch->normal);
  if (!point) return fail("finger " + std::to_string(id) + ": the point is not finite or not on the finger's plane");
  const Vec3 previous = touch->onPlane;
  touch->onPlane = *point;
  switch (touch->mode) {
    case Mode::sticky: break;  // the target follows in update()
    case Mode::cut:
      if (glm::length(*point - previous) > 0.0) {
        const Vec3 depth =
            pointer.kind == Pointer::Kind::screen
                ? glm::normalize(camera_.ray(pointer.screen.x, pointer.screen.y, aspect_).direction + touch->depth)
                : touch->depth;
        if (!touch->cutStarted && beforeCut) beforeCut();
        touch->cutStarted = true;
        if (world_.cut(previous, *point, depth) > 0) touch->cutSomething = true;
        touch->stroke.push_back(*point);
      }
      break;
    case Mode::create:
      // Samples closer than a tenth of the spacing add nothing to the outline.
      if (glm::length(*point - touch->stroke.back()) >= settings_.spacing * 0.1) touch->stroke.push_back(*point);
      break;
  }
  note(GestureEvent::Type::move, id, *point);
  return true;
}

bool Interaction::up(int id) {
  Touch* touch = find(id);
  if (!touch) return fail("finger " + std::to_string(id) + " is not down");
  const Touch lifted = *touch;
  touches_.erase(touches_.begin() + (touch - touches_.data()));
  note(GestureEvent::Type::up, id);
  if (lifted.mode == Mode::sticky && lifted.holds) world_.releaseFinger(id);
  if (lifted.mode == Mode::cut && lifted.cutStarted && !lifted.cutSomething && cutNothing) cutNothing();
  if (lifted.mode == Mode::cut && lifted.cutSomething && afterCut) afterCut(lifted.stroke);
  if (lifted.mode == Mode::create) return spawn(lifted);
  return true;
}

bool Interaction::pin(int id) {
  Touch* touch = find(id);
  if (!touch) return fail("finger " + std::to_string(id) + " is not down");
  if (touch->mode != Mode::sticky || !touch->holds) {
    return fail("finger " + std::to_string(id) + " holds no cloth to pin");
  }
  touches_.erase(touches_.begin() + (touch - touches_.data()));
  world_.pinFinger(id);
  note(GestureEvent::Type::pin, id);
  return true;
}

bool Interaction::lift(int id, Real height) {
  Touch* touch = find(id);
  if (!touch) return fail("finger " + std::to_string(id) + " is not down");
  if (!std::isfinite(height)) return fail("finger " + std::to_string(id) + ": the height is not finite");
  touch->heightGoal = height;
  if (record) {
    GestureEvent e;
    e.type = GestureEvent::Type::lift;
    e.finger = id;
    e.height = height;
    record(e);
  }
  return true;
}

bool Interaction::unpin(const Pointer& pointer, Real radius) {
  const Vec3 tableAnchor{0.0, settings_.tableHeight, 0.0};
  std::optional<Vec3> point;
  if (pointer.kind == Pointer::Kind::world) {
    point = pointOnPlane(pointer, tableAnchor, kUp);
  } else if (std::isfinite(pointer.screen.x) && std::isfinite(pointer.screen.y)) {
    // The pin nearest the ray, within the radius of it.
    const render::Ray ray = camera_.ray(pointer.screen.x, pointer.screen.y, aspect_);
    Real best = radius;
    for (const sim::Cloth& cloth : world_.cloths()) {
      for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
        if (!cloth.state.pinned[i]) continue;
        const Vec3 d = cloth.state.position[i] - ray.origin;
        const Real t = glm::dot(d, ray.direction);
        const Real off = std::sqrt(std::max(glm::dot(d, d) - t * t, 0.0));
        if (t > 0.0 && off <= best) {
          best = off;
          point = cloth.state.position[i];
        }
      }
    }
    if (!point) return fail("no pin under the pointer");
  }
  if (!point) return fail("the unpin point is not finite");
  if (world_.unpin(*point, radius) == 0) return fail("no pin within the radius");
  if (record) {
    GestureEvent e;
    e.type = GestureEvent::Type::unpin;
    e.pointer = Pointer::at(*point);
    e.radius = radius;
    record(e);
  }
  return true;
}

void Interaction::cancelAll() {
  for (const Touch& touch : touches_) {
    if (touch.mode == Mode::sticky && touch.holds) world_.releaseFinger(touch.id);
    note(GestureEvent::Type::up, touch.id);
  }
  touches_.clear();
}

void Interaction::update(Real dt) {
  for (Touch& touch : touches_) {
    if (touch.mode != Mode::sticky || !touch.holds) continue;
    bool pinched = false;
    for (const Touch& other : touches_) {
      if (&other == &touch || other.mode != Mode::sticky || !other.holds) continue;
      pinched = pinched || glm::length(other.onPlane - touch.onPlane) < settings_.pinchDistance;
    }
    const Real step = settings_.liftSpeed * dt;
    const auto approach = [step](Real value, Real goal) {
      return goal > value ? std::min(goal, value + step) : std::max(goal, value - step);
    };
    touch.pinch = approach(touch.pinch, pinched ? settings_.pinchHeight : 0.0);
    touch.height = approach(touch.height, touch.heightGoal);
    world_.moveFinger(touch.id, touch.onPlane + kUp * (touch.height + touch.pinch));
  }
}

bool Interaction::spawn(const Touch& touch) {
  mesh::OutlineSpec outline;
  for (const Vec3& p : touch.stroke) outline.points.push_back({p.x, p.z});
  outline.spacing = settings_.spacing;
  outline.height = settings_.tableHeight + settings_.clothHeight;
  try {
    mesh::OutlineMesh shape = mesh::meshOutline(outline);
    const std::size_t particles = shape.positions.size();
    sim::ClothSettings cloth = settings_.material;
    cloth.mesh = std::make_shared<const sim::LatticeMesh>(sim::LatticeMesh{
        std::move(shape.positions), std::move(shape.triangles), std::move(shape.nodes), outline.spacing});
    cloth.pins.clear();
    cloth.mass = settings_.arealDensity * loopArea(shape.loop);
    spawnedIndex_.push_back(world_.addCloth(cloth));
    if (afterSpawn) afterSpawn();
    if (tell) {
      glm::dvec2 lower = shape.loop.front(), upper = shape.loop.front();
      for (const glm::dvec2& p : shape.loop) {
        lower = glm::min(lower, p);
        upper = glm::max(upper, p);
      }
      char said[160];
      std::snprintf(said, sizeof said, "a cloth of %zu particles, %.2f m x %.2f m%s", particles, upper.x - lower.x,
                    upper.y - lower.y,
                    shape.tookLargestLoop ? " (the outline crossed itself: the largest loop was kept)" : "");
      tell(said);
    }
  } catch (const std::invalid_argument& error) {
    if (tell) tell(std::string("no cloth: ") + error.what());
    return fail(std::string("outline: ") + error.what());
  }
  return true;
}

bool Interaction::undoSpawn() {
  if (spawnedIndex_.empty()) return fail("no drawn cloth to take back");
  const int index = spawnedIndex_.back();
  spawnedIndex_.pop_back();
  // Fingers on it let go first.
  for (auto touch = touches_.begin(); touch != touches_.end();) {
    const sim::Finger* finger = world_.finger(touch->id);
    const bool onIt = finger && std::any_of(finger->grips.begin(), finger->grips.end(),
                                            [&](const sim::FingerGrip& g) { return g.cloth == index; });
    if (onIt) {
      world_.releaseFinger(touch->id);
      touch = touches_.erase(touch);
    } else {
      ++touch;
    }
  }
  world_.removeCloth(index);
  return true;
}

std::vector<TouchView> Interaction::touches() const {
  std::vector<TouchView> views;
  for (const Touch& touch : touches_) {
    views.push_back({touch.id, touch.mode, touch.onPlane + kUp * (touch.height + touch.pinch), touch.onPlane,
                     touch.stroke, touch.holds, touch.pinch > 0.0});
  }
  return views;
}

}  // namespace drape::interact
