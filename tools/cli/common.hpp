// Pieces every drape-cli subcommand shares.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <memory>

#include "commands.hpp"
#include "drape/interact/replay.hpp"
#include "drape/scene/scene.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/world.hpp"

namespace drape::cli {

// Prints "drape-cli: error: MESSAGE" and returns kExitBadInput.
int badInput(const std::string& message);

// The --out-dir folder, made if it is not there. Throws scene::InputError naming it if it cannot be.
std::filesystem::path outputFolder(const std::string& outDir);

scene::Scene loadScene(const SceneArguments& arguments);

// What run, render and validate take: a scene, or a snapshot (NAME.drape.json: the app's save, or
// `--out`'s) to go on from, whose scene is as it was saved (no --set).
struct Input {
  scene::Scene scene;
  std::optional<scene::Snapshot> snapshot;
};
Input loadInput(const SceneArguments& arguments);

// The engine validates too; its messages are a last line of defence behind the scene reader's.
sim::World makeWorld(const scene::Scene& scene);

// Steps to run: --steps, or --time / dt, or the gesture script's length / dt, or the scene's
// duration / dt; at most kMaxSteps.
std::int64_t stepCount(const scene::Scene& scene, std::optional<std::int64_t> steps, std::optional<double> seconds,
                       const interact::GestureScript* script = nullptr);

// A world, and the gesture script played on it if there is one. Stays where it is made (the
// interaction holds on to the world).
class Playback {
 public:
  Playback(const scene::Scene& scene, const std::optional<std::string>& gesture);
  // A snapshot's world, where there is one, else the scene's.
  Playback(const Input& input, const std::optional<std::string>& gesture);
  Playback(const Playback&) = delete;
  Playback& operator=(const Playback&) = delete;

  sim::StepStatus step();
  sim::World& world() { return world_; }
  const interact::GestureScript* script() const { return script_ ? &*script_ : nullptr; }
  const interact::Interaction* interaction() const { return interaction_.get(); }
  // What a summary line says of the steps taken since it was made: "N steps (T s simulated)", and
  // where the world came from a snapshot, " from its snapshot at S s" (its clock went on from there).
  std::string stepsRun() const;
  // Prints the events the replay skipped, one warning line each, to stderr.
  void printReports() const;

 private:
  sim::World world_;
  std::int64_t startStep_;  // the world's step as it was made (a snapshot's, or 0)
  bool fromSnapshot_;
  std::optional<interact::GestureScript> script_;
  std::unique_ptr<interact::Interaction> interaction_;
  std::unique_ptr<interact::Replay> replay_;
};

// `value` printed by a printf pattern of one double ("%.3f"), for the reports.
std::string format(const char* pattern, double value);
// A strain as a percentage with two decimals: 0.0512 -> "5.12 %".
std::string percent(double strain);

// Runs gnuplot on `script` in `directory`, where the script's files are named relative to it; the
// script draws to the file its variable `outfile` names, and this makes that `picture` (replaced
// whole, or not at all). Throws scene::InputError if it cannot.
void drawWithGnuplot(const std::filesystem::path& directory, const std::string& script, const std::string& picture);

// Prints where the world diverged and returns kExitDiverged.
int reportDivergence(const scene::Scene& scene, const sim::World& world);

}  // namespace drape::cli
