// What the app holds, apart from its window: the scene, the world, the fingers' interaction, the
// camera, undo, and the fixed-step clock. No SDL, no GL: tested without a window.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/interact/interaction.hpp"
#include "drape/interact/replay.hpp"
#include "drape/render/camera.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/world.hpp"

namespace drape::app {

// A fixed step driven by a wall clock: elapsed time accumulates and is spent in whole steps, at most
// `maxSteps` per frame. A frame slower than that drops the rest (the simulation runs slower than
// real time instead of spiralling: each frame catching up would take longer than the last).
class FixedStepper {
 public:
  explicit FixedStepper(int maxSteps = 4) : maxSteps_(maxSteps) {}
  // Steps to take now for `elapsed` seconds of wall time at step `dt`.
  int advance(double elapsed, double dt);
  bool fellBehind() const { return fellBehind_; }  // the last advance dropped time
  void reset() { accumulator_ = 0.0; }

 private:
  int maxSteps_;
  double accumulator_ = 0.0;
  bool fellBehind_ = false;
};

class Session {
 public:
  // Throws scene::InputError when the scene cannot be loaded.
  explicit Session(const std::filesystem::path& scene);
  Session(const Session&) = delete;  // the interaction's callbacks hold on to this session
  Session& operator=(const Session&) = delete;

  // Loads another scene (or a snapshot, *.drape.json). On failure returns the message and keeps
  // everything as it was.
  std::optional<std::string> load(const std::filesystem::path& file);
  // Writes the scene and every cloth as it is now; returns a message on failure.
  std::optional<std::string> save(const std::filesystem::path& file) const;
  // Back to the scene's start (the tuning the panels changed is kept).
  void reset();
  // Restarts the scene with another model or integrator (scene::withModel); returns a message when
  // the scene cannot run so.
  std::optional<std::string> setModel(sim::Model model, sim::Integrator integrator);
  // Restarts the scene with every sheet made of the fabric preset `name` (scene::withFabric), or,
  // with none, as the scene's file says; returns a message when it cannot run so.
  std::optional<std::string> setFabric(const std::optional<std::string>& name);
  // The preset setFabric chose, or empty: the cloths are as the scene says.
  const std::string& fabric() const { return fabric_; }
  // Applies changed settings (from the panels); returns a message when they are refused.
  std::optional<std::string> tune(const sim::WorldSettings& settings);

  // One step of the world, fingers first. On a divergence the world is back at its last good
  // positions, at rest, and the session pauses and says so in `status`.
  sim::StepStatus step();

  // Takes back the last cloth drawn, the last cut or the last tear (a tear that runs on over
  // several steps is one). A cut or tear is taken back with the motion since: every particle it
  // left in place stays where it is now, the copies it made are dropped, and the masses are as
  // before it. False when there is nothing to take back.
  bool undo();

  // Cuts just made, shown as seams for a moment (kSeamSeconds), so a cut is seen before a half
  // is lifted.
  struct Seam {
    std::vector<glm::dvec3> path;  // m
    double age = 0.0;              // s since the cut
  };
  static constexpr double kSeamSeconds = 1.5;
  const std::vector<Seam>& seams() const { return seams_; }
  // Does again what the last undo took back (a drawn cloth comes back as it was; a cut or tear
  // comes back with the motion since: each copy it made is where it was beside its particle).
  // Any new cloth, cut or tear forgets what could be redone. False when there is nothing.
  bool redo();

  // Ages the seams by `seconds` of wall time and forgets those older than kSeamSeconds.
  void ageSeams(double seconds);

  // The window the camera draws into: its aspect, and the fraction of its width the panels cover
  // on the right. Framing centres the scene in the part left uncovered.
  void setView(double aspect, double coveredRight);
  // The camera as a scene starts: the whole scene from the front right (Home), and the points
  // `alsoFrame` gave (a replayed gesture's: where its fingers go).
  void resetView();
  void alsoFrame(std::vector<glm::dvec3> points) { alsoFramed_ = std::move(points); }
  // A gesture script's world points (where it puts its fingers down and moves them).
  static std::vector<glm::dvec3> worldPoints(const interact::GestureScript& script);
  // The cloths, as they are now, filling the view from where the camera looks now (F).
  void frameCloths();
  // Keeps the eye above the table (a plane collider facing up), so orbiting cannot hide the scene
  // under it; called every frame.
  void keepCameraAboveTable();

  const scene::Scene& scene() const { return scene_; }
  sim::World& world() { return *world_; }
  const sim::World& world() const { return *world_; }
  interact::Interaction& interaction() { return *interaction_; }
  render::Camera& camera() { return camera_; }
  const std::filesystem::path& path() const { return path_; }

  // Threads that step the world (the result is the same whatever the number); kept across loads.
  void setThreads(int threads);
  int threads() const { return threads_; }

  bool paused = false;
  std::string status;  // the last thing worth telling the user (shown in the HUD)

 private:
  struct Undo {
    enum class Kind : std::uint8_t { spawn, cut, tear } kind;
    std::vector<sim::Cloth> cloths;  // cut, tear: the cloths before it
    double time = 0.0;               // tear: the world's time when it last tore on
  };
  void adopt(scene::Scene scene, std::unique_ptr<sim::World> world, const std::filesystem::path& path);
  void frame(glm::dvec3 lower, glm::dvec3 upper, double yaw, double pitch);

  scene::Scene scene_;
  std::filesystem::path path_;
  std::unique_ptr<sim::World> world_;
  std::unique_ptr<interact::Interaction> interaction_;
  render::Camera camera_;
  std::vector<Undo> undo_;
  std::vector<Undo> redo_;  // spawn: the cloth taken back; cut, tear: the cloths as the undo found them
  std::vector<Seam> seams_;
  std::vector<glm::dvec3> alsoFramed_;
  // While tearing is on: the cloths as their topology stood before the step (copied once after
  // each change of it), for undoing a tear.
  std::vector<sim::Cloth> shape_;
  std::uint64_t shapeVersion_ = 0;
  int threads_ = 1;
  double viewAspect_ = 16.0 / 10.0;
  double viewCovered_ = 0.0;
  std::string fabric_;
};

}  // namespace drape::app
