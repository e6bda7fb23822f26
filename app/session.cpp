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

namespace {

bool isSnapshot(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  return name.size() > 11 && name.substr(name.size() - 11) == ".drape.json";
}

}  // namespace

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
  interaction_->beforeCut = [this] { undo_.push_back({Undo::Kind::cut, world_->cloths()}); };
  interaction_->cutNothing = [this] {
    if (!undo_.empty() && undo_.back().kind == Undo::Kind::cut) undo_.pop_back();
  };
  interaction_->afterSpawn = [this] { undo_.push_back({Undo::Kind::spawn, {}}); };
  interaction_->tell = [this](const std::string& line) { status = line; };
  undo_.clear();
  frame();
}

void Session::frame() {
  glm::dvec3 lower, upper;
  render::sceneBounds(*world_, lower, upper);
  camera_ = render::Camera::framing(lower, upper, 0.6, 0.45, 16.0 / 10.0);
}

std::optional<std::string> Session::load(const std::filesystem::path& file) {
  try {
    if (isSnapshot(file)) {
      scene::Snapshot snapshot = scene::loadSnapshot(file);
      auto world = std::make_unique<sim::World>(scene::makeWorld(snapshot));
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
  if (isSnapshot(path_)) {
    load(path_);
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
    return std::nullopt;
  } catch (const std::invalid_argument& error) {
    status = std::string("not applied: ") + error.what();
    return status;
  }
}

sim::StepStatus Session::step() {
  interaction_->update(world_->settings().solver.dt);
  const sim::StepStatus result = world_->step();
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
  if (last.kind == Undo::Kind::spawn) {
    interaction_->cancelAll();
    interaction_->undoSpawn();
    status = "took back the last drawn cloth";
  } else {
    interaction_->cancelAll();
    world_->restoreCloths(std::move(last.cloths));
    status = "took back the last cut";
  }
  return true;
}

}  // namespace drape::app
