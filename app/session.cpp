#include "session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "drape/render/renderer.hpp"
#include "drape/scene/error.hpp"
#include "drape/scene/fabric.hpp"
#include "drape/scene/output.hpp"
#include "drape/scene/snapshot.hpp"

namespace drape::app {

int FixedStepper::advance(double elapsed, double dt) {
  if (!(elapsed > 0.0) || !std::isfinite(elapsed) || !(dt > 0.0)) return 0;
  accumulator_ += elapsed;
  const double wanted = std::floor(accumulator_ / dt);
  const int steps = static_cast<int>(std::min<double>(wanted, maxSteps_));
  accumulator_ -= steps * dt;
  fellBehind_ = wanted > maxSteps_;
  if (fellBehind_) accumulator_ = 0.0;
  return steps;
}

Session::Session(const std::filesystem::path& scene) {
  if (const std::optional<std::string> error = load(scene)) throw scene::InputError(*error);
}

void Session::setThreads(int threads) {
  threads_ = std::clamp(threads, 1, sim::kMaxThreads);
  world_->setThreads(threads_);
}

void Session::adopt(scene::Scene scene, std::unique_ptr<sim::World> world, const std::filesystem::path& path) {
  scene_ = std::move(scene);
  world_ = std::move(world);
  world_->setThreads(threads_);
  path_ = path;
  fabric_.clear();
  interaction_ = std::make_unique<interact::Interaction>(*world_);
  interaction_->settings().material = scene::drawnClothTemplate(scene_);
  interaction_->beforeCut = [this] { undo_.push_back({Undo::Kind::cut, world_->cloths().copy()}); };
  interaction_->cutNothing = [this] {
    if (!undo_.empty() && undo_.back().kind == Undo::Kind::cut) undo_.pop_back();
  };
  interaction_->afterCut = [this](const std::vector<sim::Vec3>& cutPath) {
    seams_.push_back({cutPath, 0.0});
    redo_.clear();  // a swipe that cut nothing forgets nothing
  };
  interaction_->afterSpawn = [this] {
    undo_.push_back({Undo::Kind::spawn, {}});
    redo_.clear();
  };
  interaction_->tell = [this](const std::string& line) { status = line; };
  // Nothing to hold yet (empty-table): the first thing to do is draw a cloth.
  if (world_->cloths().empty()) interaction_->setMode(interact::Mode::create);
  undo_.clear();
  redo_.clear();
  seams_.clear();
  shape_.clear();
  shapeVersion_ = 0;
  resetView();
}

namespace {

// The first n particles of `s` where they are in `current`: positions, previous positions (so
// velocities), velocities and pins; masses stay.
void takeMotion(sim::ParticleState& s, const sim::ParticleState& current, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    s.position[i] = current.position[i];
    s.previousPosition[i] = current.previousPosition[i];
    if (i < s.velocity.size() && i < current.velocity.size()) s.velocity[i] = current.velocity[i];
    s.pinned[i] = current.pinned[i];
  }
}

// `before` (the cloths as a cut or tear found them) with the motion since, from `now`: a cut or
// tear keeps each particle's index and appends its copies (topology.cpp), so the first particles
// of each cloth now are the particles before it, where they are now. Positions, previous positions
// (so velocities), velocities and pins come from now; rest data and masses from before, so the
// mass is exactly what it was. Where the cloths do not match so (a cloth fewer), `before` as it is.
std::vector<sim::Cloth> withMotionSince(std::vector<sim::Cloth> before, const sim::ClothList& now) {
  if (before.size() != now.size()) return before;
  for (std::size_t c = 0; c < before.size(); ++c) {
    if (now[c].state.position.size() < before[c].state.position.size()) return before;
  }
  for (std::size_t c = 0; c < before.size(); ++c) {
    takeMotion(before[c].state, now[c].state, before[c].state.position.size());
  }
  return before;
}

// `after` (the cloths as an undo found them, a cut or tear in them) brought to the motion since,
// from `now` (the cloths before that cut or tear): each particle that was there before it is where
// it is now, and each particle the cut or tear made (a copy, or a particle put on an edge) moves as
// the particles beside it (in `after`'s triangles, on its own side of the cut) moved on average. A
// cut or tear keeps each particle's index and appends the new ones (topology.cpp). Where the
// cloths do not match so, `after` as it is.
std::vector<sim::Cloth> withMotionAfter(std::vector<sim::Cloth> after, const sim::ClothList& now) {
  if (after.size() != now.size()) return after;
  for (std::size_t c = 0; c < after.size(); ++c) {
    if (after[c].state.position.size() < now[c].state.position.size()) return after;
  }
  for (std::size_t c = 0; c < after.size(); ++c) {
    sim::ParticleState& s = after[c].state;
    const sim::ParticleState& current = now[c].state;
    const std::size_t n = current.position.size(), total = s.position.size();
    // How far each particle has moved since the undo: known for those there before.
    std::vector<sim::Vec3> moved(total, sim::Vec3{0.0}), movedBefore(total, sim::Vec3{0.0});
    std::vector<std::uint8_t> known(total, 0);
    for (std::size_t i = 0; i < n; ++i) {
      moved[i] = current.position[i] - s.position[i];
      movedBefore[i] = current.previousPosition[i] - s.previousPosition[i];
      known[i] = 1;
    }
    // The new ones from their neighbours, ring by ring (a new particle may touch only new ones).
    const std::vector<glm::uvec3>& triangles = after[c].rest.triangles;
    for (bool progress = true; progress;) {
      progress = false;
      std::vector<sim::Vec3> sum(total, sim::Vec3{0.0}), sumBefore(total, sim::Vec3{0.0});
      std::vector<int> count(total, 0);
      for (const glm::uvec3& t : triangles) {
        for (int k = 0; k < 3; ++k) {
          const std::size_t j = t[k];
          if (j >= total || known[j]) continue;
          for (int e = 1; e < 3; ++e) {
            const std::size_t i = t[(k + e) % 3];
            if (i >= total || !known[i]) continue;
            sum[j] += moved[i];
            sumBefore[j] += movedBefore[i];
            ++count[j];
          }
        }
      }
      for (std::size_t j = n; j < total; ++j) {
        if (known[j] || count[j] == 0) continue;
        moved[j] = sum[j] / static_cast<double>(count[j]);
        movedBefore[j] = sumBefore[j] / static_cast<double>(count[j]);
        known[j] = 1;
        progress = true;
      }
    }
    for (std::size_t j = n; j < total; ++j) {
      s.position[j] += moved[j];
      s.previousPosition[j] += movedBefore[j];
    }
    takeMotion(s, current, n);
  }
  return after;
}

constexpr double kYaw = 0.6, kPitch = 0.45;  // from the front right, a little above

// The height of the table: the highest plane collider facing (nearly) up, if there is one.
std::optional<double> tableHeight(const sim::World& world) {
  std::optional<double> height;
  for (const sim::Collider& collider : world.colliders()) {
    const sim::ColliderSettings& s = collider.settings();
    if (s.shape != sim::ColliderShape::plane) continue;
    const glm::dvec3 up = s.orientation * s.normal;
    if (glm::length(up) > 0.0 && glm::normalize(up).y > 0.99) {
      height = std::max(height.value_or(-1e300), collider.centre().y);
    }
  }
  return height;
}

}  // namespace

void Session::setView(double aspect, double coveredRight) {
  if (aspect > 0.0 && std::isfinite(aspect)) viewAspect_ = aspect;
  if (std::isfinite(coveredRight)) viewCovered_ = std::clamp(coveredRight, 0.0, 0.7);
}

void Session::frame(glm::dvec3 lower, glm::dvec3 upper, double yaw, double pitch) {
  const double uncovered = 1.0 - viewCovered_;
  camera_ = render::Camera::framing(lower, upper, yaw, pitch, viewAspect_ * uncovered);
  // Centred in the part of the window the panels leave: the eye moves right by half the covered
  // part's width at the target's distance, so the scene moves left.
  const double halfWidth = std::tan(camera_.fieldOfView / 2.0) * viewAspect_;  // in camera distances
  camera_.pan(halfWidth * viewCovered_, 0.0);
}

void Session::resetView() {
  glm::dvec3 lower, upper;
  // A collider that moves (rising-sphere's ball, which lifts the cloth a metre in its 4 s) framed
  // where the scene's duration takes it too; and nothing under the table, which hides it (the ball
  // starts there).
  render::sceneBounds(*world_, lower, upper, scene_.duration);
  for (const glm::dvec3& point : alsoFramed_) {
    lower = glm::min(lower, point);
    upper = glm::max(upper, point);
  }
  if (const std::optional<double> table = tableHeight(*world_); table && *table < upper.y) {
    lower.y = std::max(lower.y, *table);
  }
  const bool onlyTable =
      world_->cloths().empty() &&
      std::all_of(world_->colliders().begin(), world_->colliders().end(),
                  [](const sim::Collider& c) { return c.settings().shape == sim::ColliderShape::plane; });
  if (onlyTable) {
    // Nothing on the table: 80 cm of it, so that an outline a quarter of the window wide makes a
    // cloth about half a metre across, as the desk's (sceneBounds would frame two metres and more).
    const double y = tableHeight(*world_).value_or(0.0);
    lower = glm::dvec3{-0.4, y, -0.4};
    upper = glm::dvec3{0.4, y + 0.1, 0.4};
  }
  frame(lower, upper, kYaw, kPitch);
}

std::vector<glm::dvec3> Session::worldPoints(const interact::GestureScript& script) {
  std::vector<glm::dvec3> points;
  for (const interact::GestureEvent& e : script.events) {
    if (e.pointer && e.pointer->kind == interact::Pointer::Kind::world) points.push_back(e.pointer->world);
  }
  return points;
}

void Session::frameCloths() {
  glm::dvec3 lower, upper;
  render::clothBounds(*world_, lower, upper);
  if (lower.x > upper.x) {
    status = "no cloth to frame";
    return;
  }
  frame(lower, upper, camera_.yaw, camera_.pitch);
  status = "framed the cloth";
}

void Session::keepCameraAboveTable() {
  const std::optional<double> table = tableHeight(*world_);
  if (!table) return;
  // The eye is at target.y + distance sin(pitch): at least 1 cm over the table.
  const double lowest = std::clamp((*table + 0.01 - camera_.target.y) / camera_.distance, -1.0, 1.0);
  camera_.pitch = std::clamp(std::max(camera_.pitch, std::asin(lowest)), -1.5, 1.5);
}

std::optional<std::string> Session::load(const std::filesystem::path& file) {
  try {
    if (scene::isSnapshotName(file)) {
      scene::Snapshot snapshot = scene::loadSnapshot(file);
      auto world = std::make_unique<sim::World>(scene::makeWorld(snapshot));
      alsoFramed_.clear();  // a replayed gesture's points were the first scene's
      adopt(std::move(snapshot.scene), std::move(world), file);
      status = "loaded " + file.string();
      return std::nullopt;
    }
    scene::Scene loaded = scene::loadScene(scene::resolveScenePath(file.string()));
    std::unique_ptr<sim::World> world;
    try {
      world = std::make_unique<sim::World>(loaded.world);
    } catch (const std::invalid_argument& error) {
      throw scene::InputError(loaded.source + ": " + error.what());
    }
    alsoFramed_.clear();
    adopt(std::move(loaded), std::move(world), file);
    status = "loaded " + scene_.name;
    return std::nullopt;
  } catch (const scene::InputError& error) {
    status = error.what();
    return status;
  }
}

std::optional<std::string> Session::save(const std::filesystem::path& file) const {
  try {
    scene::writeFileAtomically(file, scene::snapshotDocument(scene_, *world_).dump() + "\n");
    return std::nullopt;
  } catch (const scene::InputError& error) {
    return std::string(error.what());
  }
}

void Session::reset() {
  const sim::WorldSettings tuned = world_->settings();
  if (scene::isSnapshotName(path_)) {
    const render::Camera keep = camera_;
    if (!load(path_)) camera_ = keep;
  } else {
    auto world = std::make_unique<sim::World>(scene_.world);
    const render::Camera keep = camera_;
    adopt(scene_, std::move(world), path_);
    camera_ = keep;
  }
  tune(tuned);
  status = "reset";
}

std::optional<std::string> Session::setModel(sim::Model model, sim::Integrator integrator) {
  scene::Scene changed = scene::withModel(scene_, model, integrator);
  // What the panels tuned of the air and gravity means the same in either model: it stays.
  changed.world.gravity = world_->settings().gravity;
  changed.world.air = world_->settings().air;
  try {
    auto world = std::make_unique<sim::World>(changed.world);
    const render::Camera keep = camera_;
    adopt(std::move(changed), std::move(world), path_);
    camera_ = keep;
  } catch (const std::invalid_argument& error) {
    status = std::string("not applied: ") + error.what();
    return status;
  }
  status = "model: " + std::string(sim::name(model)) +
           (model == sim::Model::force ? " (" + std::string(sim::name(integrator)) + ", " +
                                             std::to_string(world_->settings().solver.substeps) + " substeps)"
                                       : std::string()) +
           ", from the start";
  return std::nullopt;
}

std::optional<std::string> Session::setFabric(const std::optional<std::string>& name) {
  const render::Camera keep = camera_;
  if (!name) {
    if (const std::optional<std::string> failed = load(path_)) return failed;
    camera_ = keep;
    status = "fabric: as the scene says, from the start";
    return std::nullopt;
  }
  try {
    scene::Scene changed = scene::withFabric(scene_, *name);
    const auto& cloths = changed.world.cloths;
    if (std::none_of(cloths.begin(), cloths.end(), [](const sim::ClothSettings& c) { return c.fabric.has_value(); })) {
      status = "not applied: " + scene_.name + " has no sheet to make of " + *name;
      return status;
    }
    auto world = std::make_unique<sim::World>(changed.world);
    adopt(std::move(changed), std::move(world), path_);
  } catch (const std::invalid_argument& error) {
    status = std::string("not applied: ") + error.what();
    return status;
  }
  camera_ = keep;
  fabric_ = *name;
  const sim::Fabric f = scene::fabricPreset(*name).value();
  char numbers[160];
  std::snprintf(numbers, sizeof numbers, " (%.0f g/m^2, bending %.2g N m), from the start", 1000.0 * f.arealDensity,
                f.bendingRigidity);
  status = "fabric: " + *name + numbers;
  return std::nullopt;
}

std::optional<std::string> Session::tune(const sim::WorldSettings& settings) {
  try {
    world_->tune(settings);
    // What a value half typed was refused for (a threshold of "1" on the way to "1.3") no longer
    // holds once a value is taken: the line said it was not applied after it was.
    if (status.rfind("not applied: ", 0) == 0) status.clear();
    return std::nullopt;
  } catch (const std::invalid_argument& error) {
    status = std::string("not applied: ") + error.what();
    return status;
  }
}

sim::StepStatus Session::step() {
  interaction_->update(world_->settings().solver.dt);
  const bool tearing = world_->settings().tearing.enabled;
  const std::uint64_t version = world_->topologyVersion();
  if (tearing && version != shapeVersion_) {
    shape_ = world_->cloths().copy();
    shapeVersion_ = version;
  }
  const sim::StepStatus result = world_->step();
  if (tearing && world_->topologyVersion() != version && result == sim::StepStatus::ok) {
    // Torn in this step. A tear running on (within half a second of its last step) stays one undo.
    const double now = world_->time();
    if (!undo_.empty() && undo_.back().kind == Undo::Kind::tear && now - undo_.back().time < 0.5) {
      undo_.back().time = now;
    } else {
      undo_.push_back({Undo::Kind::tear, std::move(shape_), now});
    }
    redo_.clear();
    shape_.clear();
    shapeVersion_ = 0;
  }
  if (result == sim::StepStatus::diverged) {
    const sim::Divergence d = *world_->divergence();
    status = "diverged at step " + std::to_string(d.step) + " (cloth " + std::to_string(d.cloth) + " particle " +
             std::to_string(d.particle) + "): back to the last good positions, at rest, paused";
    interaction_->cancelAll();
    world_->clearDivergence();
    paused = true;
  }
  return result;
}

bool Session::undo() {
  if (undo_.empty()) {
    status = "nothing to undo";
    return false;
  }
  Undo last = std::move(undo_.back());
  undo_.pop_back();
  interaction_->cancelAll();
  if (last.kind == Undo::Kind::spawn) {
    const std::optional<int> index = interaction_->lastSpawned();
    if (index) redo_.push_back({Undo::Kind::spawn, {world_->cloths()[static_cast<std::size_t>(*index)]}});
    interaction_->undoSpawn();
    status = "took back the last drawn cloth";
  } else {
    redo_.push_back({last.kind, world_->cloths().copy()});
    world_->restoreCloths(withMotionSince(std::move(last.cloths), world_->cloths()));
    status = last.kind == Undo::Kind::cut ? "took back the last cut" : "took back the last tear";
  }
  shapeVersion_ = 0;
  return true;
}

bool Session::redo() {
  if (redo_.empty()) {
    status = "nothing to redo";
    return false;
  }
  Undo next = std::move(redo_.back());
  redo_.pop_back();
  interaction_->cancelAll();
  if (next.kind == Undo::Kind::spawn) {
    std::vector<sim::Cloth> cloths = world_->cloths().copy();
    cloths.push_back(std::move(next.cloths.front()));
    world_->restoreCloths(std::move(cloths));
    interaction_->noteSpawned(static_cast<int>(world_->cloths().size()) - 1);
    undo_.push_back({Undo::Kind::spawn, {}});
    status = "put back the drawn cloth";
  } else {
    undo_.push_back({next.kind, world_->cloths().copy(), world_->time()});
    world_->restoreCloths(withMotionAfter(std::move(next.cloths), world_->cloths()));
    status = next.kind == Undo::Kind::cut ? "did the cut again" : "did the tear again";
  }
  shapeVersion_ = 0;
  return true;
}

void Session::ageSeams(double seconds) {
  for (Seam& seam : seams_) seam.age += std::isfinite(seconds) ? std::max(seconds, 0.0) : 0.0;
  std::erase_if(seams_, [](const Seam& seam) { return seam.age > kSeamSeconds; });
}

}  // namespace drape::app
