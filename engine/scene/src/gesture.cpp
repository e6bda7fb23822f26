#include "drape/scene/gesture.hpp"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/sim/world.hpp"
#include "json_reader.hpp"

namespace drape::scene {

namespace {

using interact::GestureEvent;
using interact::Pointer;
using nlohmann::json;

constexpr std::size_t kMaxEvents = 1000000;

render::Camera readCamera(ObjectReader& reader, double& aspect) {
  render::Camera camera;
  camera.target = reader.vec3("target", camera.target, kMaxCoordinate, "m");
  camera.yaw = reader.number("yaw", camera.yaw / kDegrees, {-360.0, 360.0, false, "degrees"}) * kDegrees;
  camera.pitch = reader.number("pitch", camera.pitch / kDegrees, {-85.0, 85.0, false, "degrees"}) * kDegrees;
  camera.distance = reader.number("distance", camera.distance, {0.05, 1000.0, false, "m"});
  camera.fieldOfView = reader.number("fov", camera.fieldOfView / kDegrees, {1.0, 170.0, false, "degrees"}) * kDegrees;
  aspect = reader.number("aspect", aspect, {0.1, 10.0, false, "width / height"});
  reader.finish();
  return camera;
}

// The event's pointer: "at" [x, y, z] in the world or "screen" [x, y] in the picture, exactly one.
Pointer readPointer(ObjectReader& event, bool haveCamera) {
  const bool at = event.has("at"), screen = event.has("screen");
  if (at == screen) event.fail(at ? "screen" : "at", "exactly one of \"at\" [x, y, z] or \"screen\" [x, y]", nullptr);
  if (at) return Pointer::at(event.vec3("at", sim::Vec3{0.0}, kMaxCoordinate, "m"));
  const json& value = *event.raw("screen");
  const bool ok = value.is_array() && value.size() == 2 && value[0].is_number() && value[1].is_number() &&
                  std::isfinite(value[0].get<double>()) && std::isfinite(value[1].get<double>()) &&
                  std::abs(value[0].get<double>()) <= 10.0 && std::abs(value[1].get<double>()) <= 10.0;
  if (!ok) event.fail("screen", "[x, y]: the picture's coordinates from the top left, 0..1 inside it", &value);
  if (!haveCamera) event.fail("screen", "a \"camera\" in the script to see the screen through", &value);
  (void)event.array("screen", 2);  // marks the key as read
  return Pointer::onScreen(value[0].get<double>(), value[1].get<double>());
}

}  // namespace

interact::GestureScript parseGesture(const json& document, const std::string& source) {
  interact::GestureScript script;
  script.source = source;
  ObjectReader root(document, "", source);
  // A scene or a snapshot where a script goes: said as what it is, not as its first unknown key.
  if (root.has("drapeSnapshot") || (root.has("cloths") && !root.has("events"))) {
    const char* what = root.has("drapeSnapshot")                  ? "a snapshot"
                       : root.has("steps") && root.has("metrics") ? "a state drape-cli wrote"
                                                                  : "a scene";
    throw InputError(source + ": " + what + ", not a gesture script (one is {\"events\": [...]}: docs/gestures.md)");
  }
  (void)root.text("description", "");
  if (root.has("duration")) script.duration = root.number("duration", 1.0, {0.0, 1.0e5, true, "s"});
  if (root.has("camera")) {
    ObjectReader camera = root.object("camera");
    script.camera = readCamera(camera, script.aspect);
  }
  interact::InteractionSettings& settings = script.settings;
  if (root.has("finger")) {
    ObjectReader finger = root.object("finger");
    settings.radius = finger.number("radius", settings.radius, {0.0, 10.0, true, "m"});
    settings.plane = *interact::parsePlane(finger.choice("plane", "table", {"table", "view"}));
    settings.pinchDistance = finger.number("pinchDistance", settings.pinchDistance, {0.0, 10.0, false, "m"});
    settings.pinchHeight = finger.number("pinchHeight", settings.pinchHeight, {0.0, 10.0, false, "m"});
    settings.liftSpeed = finger.number("liftSpeed", settings.liftSpeed, {0.0, 100.0, true, "m/s"});
    finger.finish();
  }
  if (root.has("draw")) {
    ObjectReader draw = root.object("draw");
    settings.spacing = draw.number("spacing", settings.spacing, {1.0e-3, 10.0, false, "m"});
    settings.tableHeight = draw.number("table", settings.tableHeight, {-kMaxCoordinate, kMaxCoordinate, false, "m"});
    settings.clothHeight = draw.number("height", settings.clothHeight, {0.0, 10.0, false, "m"});
    settings.arealDensity = draw.number("density", settings.arealDensity, {1.0e-4, 100.0, false, "kg/m^2"});
    draw.finish();
  }
  const interact::Mode startMode = *interact::parseMode(root.choice("mode", "sticky", {"sticky", "cut", "create"}));
  if (startMode != interact::Mode::sticky) {
    script.events.push_back({0.0, GestureEvent::Type::mode, 0, std::nullopt, std::nullopt, 0.0, startMode, {}});
  }

  const json& events = root.array("events", kMaxEvents);
  double previous = 0.0;
  std::set<int> down;  // fingers down at this point of the script
  for (std::size_t i = 0; i < events.size(); ++i) {
    ObjectReader event(events[i], "events." + std::to_string(i), source);
    GestureEvent e;
    if (!event.has("time")) event.fail("time", "the event's time in seconds", nullptr);
    e.time = event.number("time", 0.0, {0.0, 1.0e5, false, "s"});
    if (e.time < previous) {
      event.fail("time", "a time no earlier than the event before (" + std::to_string(previous) + " s)",
                 event.raw("time"));
    }
    previous = e.time;
    if (!event.has("type")) event.fail("type", "one of down, move, up, pin, unpin, lift, mode, plane", nullptr);
    const std::string type =
        event.choice("type", "move", {"down", "move", "up", "pin", "unpin", "lift", "mode", "plane"});
    const auto needFinger = [&] {
      if (!event.has("finger")) event.fail("finger", "the finger's id (an integer)", nullptr);
      e.finger = event.integer("finger", 0, 0, 1000000000);
    };
    if (type == "down") {
      e.type = GestureEvent::Type::down;
      needFinger();
      if (down.insert(e.finger).second && down.size() > static_cast<std::size_t>(sim::kMaxFingers)) {
        event.fail("finger", "at most " + std::to_string(sim::kMaxFingers) + " fingers down at once",
                   event.raw("finger"));
      }
      e.pointer = readPointer(event, script.camera.has_value());
      if (event.has("radius")) e.radius = event.number("radius", 0.05, {0.0, 10.0, true, "m"});
    } else if (type == "move") {
      e.type = GestureEvent::Type::move;
      needFinger();
      e.pointer = readPointer(event, script.camera.has_value());
    } else if (type == "up" || type == "pin") {
      e.type = type == "up" ? GestureEvent::Type::up : GestureEvent::Type::pin;
      needFinger();
      down.erase(e.finger);
    } else if (type == "unpin") {
      e.type = GestureEvent::Type::unpin;
      e.pointer = readPointer(event, script.camera.has_value());
      if (event.has("radius")) e.radius = event.number("radius", 0.05, {0.0, 10.0, true, "m"});
    } else if (type == "lift") {
      e.type = GestureEvent::Type::lift;
      needFinger();
      if (!event.has("height")) event.fail("height", "the finger's height above its plane in metres", nullptr);
      e.height = event.number("height", 0.0, {-100.0, 100.0, false, "m"});
    } else if (type == "mode") {
      e.type = GestureEvent::Type::mode;
      if (!event.has("mode")) event.fail("mode", "one of sticky, cut, create", nullptr);
      e.mode = *interact::parseMode(event.choice("mode", "sticky", {"sticky", "cut", "create"}));
    } else {
      e.type = GestureEvent::Type::plane;
      if (!event.has("plane")) event.fail("plane", "one of table, view", nullptr);
      e.plane = *interact::parsePlane(event.choice("plane", "table", {"table", "view"}));
    }
    event.finish();
    script.events.push_back(e);
  }
  root.finish();
  return script;
}

interact::GestureScript loadGesture(const std::filesystem::path& file) {
  return parseGesture(readJsonFile(file, "gesture script", kMaxGestureFileBytes), file.string());
}

json gestureDocument(const interact::GestureScript& script) {
  json document;
  if (script.duration) document["duration"] = *script.duration;
  if (script.camera) {
    const render::Camera& c = *script.camera;
    document["camera"] = {{"target", {c.target.x, c.target.y, c.target.z}},
                          {"yaw", c.yaw / kDegrees},
                          {"pitch", c.pitch / kDegrees},
                          {"distance", c.distance},
                          {"fov", c.fieldOfView / kDegrees},
                          {"aspect", script.aspect}};
  }
  const interact::InteractionSettings& s = script.settings;
  document["finger"] = {{"radius", s.radius},
                        {"plane", std::string(interact::name(s.plane))},
                        {"pinchDistance", s.pinchDistance},
                        {"pinchHeight", s.pinchHeight},
                        {"liftSpeed", s.liftSpeed}};
  document["draw"] = {
      {"spacing", s.spacing}, {"table", s.tableHeight}, {"height", s.clothHeight}, {"density", s.arealDensity}};
  json events = json::array();
  for (const GestureEvent& e : script.events) {
    json event = {{"time", e.time}, {"type", std::string(interact::name(e.type))}};
    switch (e.type) {
      case GestureEvent::Type::down:
      case GestureEvent::Type::move:
      case GestureEvent::Type::up:
      case GestureEvent::Type::pin:
      case GestureEvent::Type::lift: event["finger"] = e.finger; break;
      default: break;
    }
    if (e.pointer) {
      if (e.pointer->kind == Pointer::Kind::world) {
        event["at"] = {e.pointer->world.x, e.pointer->world.y, e.pointer->world.z};
      } else {
        event["screen"] = {e.pointer->screen.x, e.pointer->screen.y};
      }
    }
    if (e.radius) event["radius"] = *e.radius;
    if (e.type == GestureEvent::Type::lift) event["height"] = e.height;
    if (e.type == GestureEvent::Type::mode) event["mode"] = std::string(interact::name(e.mode));
    if (e.type == GestureEvent::Type::plane) event["plane"] = std::string(interact::name(e.plane));
    events.push_back(std::move(event));
  }
  document["events"] = std::move(events);
  return document;
}

}  // namespace drape::scene
