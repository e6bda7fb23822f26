#include "common.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <vector>

#include <spawn.h>
#include <sys/wait.h>

#include "drape/scene/error.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/input.hpp"
#include "drape/scene/output.hpp"

namespace drape::cli {

int badInput(const std::string& message) {
  std::cerr << "drape-cli: error: " << message << "\n";
  return kExitBadInput;
}

std::filesystem::path outputFolder(const std::string& outDir) {
  const std::filesystem::path directory = outDir;
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (!std::filesystem::is_directory(directory, error))
    throw scene::InputError(outDir + ": cannot create the folder for --out-dir");
  return directory;
}

scene::Scene loadScene(const SceneArguments& arguments) {
  return scene::loadScene(scene::resolveScenePath(arguments.scene), arguments.overrides);
}

Input loadInput(const SceneArguments& arguments) {
  const std::filesystem::path file = scene::resolveScenePath(arguments.scene);
  if (!scene::isSnapshotName(file)) return {loadScene(arguments), std::nullopt};
  if (!arguments.overrides.empty()) {
    throw scene::InputError("--set " + scene::printable(arguments.overrides.front(), 200) + ": " +
                            scene::printable(file.string(), 200) +
                            " is a snapshot, whose scene is as it was saved: set keys on a scene file");
  }
  scene::Snapshot snapshot = scene::loadSnapshot(file);
  scene::Scene scene = snapshot.scene;
  return {std::move(scene), std::move(snapshot)};
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

Playback::Playback(const scene::Scene& scene, const std::optional<std::string>& gesture)
    : Playback(Input{scene, std::nullopt}, gesture) {}

Playback::Playback(const Input& input, const std::optional<std::string>& gesture)
    : world_(input.snapshot ? scene::makeWorld(*input.snapshot) : makeWorld(input.scene)),
      startStep_(world_.stepCount()),
      fromSnapshot_(input.snapshot.has_value()) {
  if (!gesture) return;
  script_ = scene::loadGesture(*gesture);
  interaction_ = std::make_unique<interact::Interaction>(world_);
  replay_ = std::make_unique<interact::Replay>(world_, *interaction_, *script_);
  interaction_->settings().material = scene::drawnClothTemplate(input.scene);
}

std::string Playback::stepsRun() const {
  const double dt = world_.settings().solver.dt;
  const std::int64_t steps = world_.stepCount() - startStep_;
  char text[160];
  std::snprintf(text, sizeof text, "%lld steps (%.3f s simulated)", static_cast<long long>(steps),
                static_cast<double>(steps) * dt);
  std::string said = text;
  if (fromSnapshot_) {
    std::snprintf(text, sizeof text, " from its snapshot at %.3f s", static_cast<double>(startStep_) * dt);
    said += text;
  }
  return said;
}

sim::StepStatus Playback::step() { return replay_ ? replay_->step() : world_.step(); }

void Playback::printReports() const {
  if (!replay_) return;
  for (const std::string& report : replay_->reports()) std::cerr << "drape-cli: warning: " << report << "\n";
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string percent(double strain) { return format("%.2f %%", 100.0 * strain); }

void drawWithGnuplot(const std::filesystem::path& directory, const std::string& script, const std::string& picture) {
  const std::string shown = scene::printable((directory / picture).string(), 200);
  // Drawn to a temporary of our own, renamed into place: the picture appears whole or not at all.
  scene::OutputBatch batch;
  const std::filesystem::path temporary = batch.reserve(directory / picture);
  // No shell: gnuplot is started with its arguments as they are, in the folder, so no character
  // of the folder's name is ever read as a command (the scripts name their files relative to it).
  std::vector<std::string> words{"gnuplot", "-e", "outfile='" + temporary.filename().string() + "'", script};
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addchdir_np(&actions, directory.c_str());
  pid_t child = 0;
  const int spawned = posix_spawnp(&child, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  if (spawned == 0) {
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (spawned != 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw scene::InputError("gnuplot could not draw " + shown + " (is gnuplot installed? tools/setup installs it)");
  }
  batch.commit();
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
