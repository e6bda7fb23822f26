#include "common.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "drape/scene/error.hpp"
#include "drape/scene/gesture.hpp"

namespace drape::cli {

int badInput(const std::string& message) {
  std::cerr << "drape-cli: error: " << message << "\n";
  return kExitBadInput;
}

scene::Scene loadScene(const SceneArguments& arguments) {
  return scene::loadScene(scene::resolveScenePath(arguments.scene), arguments.overrides);
}

sim::World makeWorld(const scene::Scene& scene) {
  try {
    return sim::World(scene.world);
  } catch (const std::invalid_argument& error) {
    throw scene::InputError(scene.source + ": " + error.what());
  }
}

std::int64_t stepCount(const scene::Scene& scene, std::optional<std::int64_t> steps, std::optional<double> seconds,
                       const interact::GestureScript* script) {
  const double length = seconds ? *seconds : script ? script->length() : scene.duration;
  const double wanted = steps ? static_cast<double>(*steps) : std::ceil(length / scene.world.solver.dt - 1e-9);
  if (!(wanted <= kMaxSteps)) {
    char count[64];
    std::snprintf(count, sizeof count, "%.0f", wanted);
    throw scene::InputError(scene.source + ": " +
                            (seconds  ? "--time"
                             : script ? "the gesture's length"
                                      : "duration") +
                            " / solver.dt asks for " + count + " steps, more than the limit of " +
                            std::to_string(static_cast<long long>(kMaxSteps)));
  }
  return static_cast<std::int64_t>(wanted);
}

Playback::Playback(const scene::Scene& scene, const std::optional<std::string>& gesture) : world_(makeWorld(scene)) {
  if (!gesture) return;
  script_ = scene::loadGesture(*gesture);
  interaction_ = std::make_unique<interact::Interaction>(world_);
  replay_ = std::make_unique<interact::Replay>(world_, *interaction_, *script_);
  interaction_->settings().material = scene::drawnClothTemplate(scene);
}

sim::StepStatus Playback::step() { return replay_ ? replay_->step() : world_.step(); }

void Playback::printReports() const {
  if (!replay_) return;
  for (const std::string& report : replay_->reports()) std::cerr << "drape-cli: warning: " << report << "\n";
}

void drawWithGnuplot(const std::filesystem::path& script, const std::filesystem::path& picture) {
  const std::string command = "gnuplot '" + script.string() + "'";
  if (std::system(command.c_str()) != 0) {
    throw scene::InputError("gnuplot could not draw " + picture.string() +
                            " (is gnuplot installed? tools/setup installs it)");
  }
}

int reportDivergence(const scene::Scene& scene, const sim::World& world) {
  const sim::Divergence& d = *world.divergence();
  std::cerr << "drape-cli: error: " << scene.source << ": diverged at step " << d.step
            << " (t = " << static_cast<double>(d.step) * scene.world.solver.dt << " s): cloth " << d.cloth
            << " particle " << d.particle << " became non-finite or ran away (past " << sim::kRunawayDistance
            << " m or " << sim::kRunawaySpeed << " m/s); nothing written\n";
  return kExitDiverged;
}

}  // namespace drape::cli
