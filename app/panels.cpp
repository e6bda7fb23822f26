#include "panels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include <imgui.h>

#include "drape/scene/fabric.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::app {

namespace {

const char* const kHelp[][2] = {
    {"touch", "a sticky finger (draws in Create mode, cuts in Cut mode); any number at once"},
    {"left drag", "a finger"},
    {"Shift + left drag", "a finger that stays down when the button is released"},
    {"Ctrl + left click", "lift the parked finger nearest the pointer"},
    {"wheel", "lift (or lower) the finger being dragged, else the last parked; with none, zoom"},
    {"right drag / middle drag", "orbit / pan the camera"},
    {"1 / 2 / 3", "Sticky / Cut / Create mode"},
    {"V", "fingers move in the table plane or the view plane"},
    {"Space / N", "pause / one step while paused"},
    {"R", "reset the scene"},
    {"U or Ctrl+Z", "undo the last drawn cloth or cut"},
    {"P or F12", "screenshot (drape-screenshot-NNN.png)"},
    {"Ctrl+S / Ctrl+O", "save / load the file named in the panel"},
    {"Tab / H or F1", "hide the panels / this help"},
    {"Esc or Ctrl+Q", "quit"},
};

std::vector<std::filesystem::path> shippedScenes() {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(scene::sceneDirectory(), error)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool sliderReal(const char* label, double& value, double low, double high, const char* format = "%.3f",
                ImGuiSliderFlags flags = 0) {
  float f = static_cast<float>(value);
  if (!ImGui::SliderFloat(label, &f, static_cast<float>(low), static_cast<float>(high), format, flags)) return false;
  value = f;
  return true;
}

bool vector3(const char* label, sim::Vec3& value, float speed) {
  float v[3] = {static_cast<float>(value.x), static_cast<float>(value.y), static_cast<float>(value.z)};
  if (!ImGui::DragFloat3(label, v, speed)) return false;
  value = sim::Vec3{v[0], v[1], v[2]};
  return true;
}

void hud(Session& session, const PanelState& panels, const FrameStats& stats) {
  ImGui::SetNextWindowPos(ImVec2(10, 10));
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("HUD", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs);
  const interact::Interaction& interaction = session.interaction();
  const double fps = stats.frameSeconds > 0.0 ? 1.0 / stats.frameSeconds : 0.0;
  ImGui::Text("%s   %.0f fps   t = %.2f s%s", session.scene().name.c_str(), fps, session.world().time(),
              session.paused ? "   PAUSED" : "");
  ImGui::Text("mode: %s (%s plane)   fingers: %zu", std::string(interact::name(interaction.mode())).c_str(),
              std::string(interact::name(interaction.settings().plane)).c_str(), session.world().fingers().size());
  ImGui::Text("simulation %.1f ms (%d steps), drawing %.1f ms per frame", stats.simulationSeconds * 1e3, stats.steps,
              stats.drawSeconds * 1e3);
  ImGui::Text("  drawing: scene %.1f ms, panels %.1f ms, presenting %.1f ms", stats.sceneSeconds * 1e3,
              stats.panelSeconds * 1e3, stats.swapSeconds * 1e3);
  if (fps > 0.0 && fps < 55.0) {
    // Say why, in the terms the user can act on.
    const bool simulation = stats.simulationSeconds > stats.drawSeconds;
    ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "below 60 fps: %s takes most of each frame%s",
                       simulation ? "the simulation" : "drawing (software GL)",
                       simulation ? " (fewer iterations or substeps, or a smaller cloth)" : "");
  }
  if (stats.fellBehind) ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "slower than real time");
  if (!session.status.empty()) ImGui::TextWrapped("%s", session.status.c_str());
  if (!panels.showHelp) ImGui::TextDisabled("F1: help");
  ImGui::End();
}

void help() {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(display.x * 0.5f, display.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::Begin("Help", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
  if (ImGui::BeginTable("bindings", 2)) {
    for (const auto& row : kHelp) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(row[0]);
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(row[1]);
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

}  // namespace

void History::add(float value) {
  values_[static_cast<std::size_t>(next_)] = value;
  next_ = (next_ + 1) % kLength;
}

float History::largest() const { return *std::max_element(values_.begin(), values_.end()); }

void FrameStats::simulation(double seconds, int stepsTaken, bool behind) {
  simulationSeconds = seconds;
  steps = stepsTaken;
  fellBehind = behind;
  stepMilliseconds.add(static_cast<float>(seconds * 1e3));
}

void FrameStats::drawing(double seconds, double frame) {
  drawSeconds = seconds;
  // A smoothed frame time, so the fps shown does not flicker.
  if (frame > 0.0) frameSeconds = frameSeconds * 0.9 + frame * 0.1;
  drawMilliseconds.add(static_cast<float>(seconds * 1e3));
  fps.add(static_cast<float>(frameSeconds > 0.0 ? 1.0 / frameSeconds : 0.0));
}

void applyKey(KeyAction action, Session& session, PanelState& panels) {
  switch (action) {
    case KeyAction::pause: session.paused = !session.paused; break;
    case KeyAction::reset: session.reset(); break;
    case KeyAction::undo: session.undo(); break;
    case KeyAction::sticky: session.interaction().setMode(interact::Mode::sticky); break;
    case KeyAction::cut: session.interaction().setMode(interact::Mode::cut); break;
    case KeyAction::create: session.interaction().setMode(interact::Mode::create); break;
    case KeyAction::plane:
      session.interaction().setPlane(session.interaction().settings().plane == interact::FingerPlane::table
                                         ? interact::FingerPlane::view
                                         : interact::FingerPlane::table);
      break;
    case KeyAction::help: panels.showHelp = !panels.showHelp; break;
    case KeyAction::panels: panels.showPanels = !panels.showPanels; break;
    case KeyAction::save: {
      const std::optional<std::string> error = session.save(panels.file);
      session.status = error ? *error : "saved " + panels.file;
      break;
    }
    case KeyAction::load: session.load(panels.file); break;
    case KeyAction::none:
    case KeyAction::step:
    case KeyAction::screenshot:
    case KeyAction::quit: break;
  }
}

std::optional<std::filesystem::path> drawPanels(Session& session, PanelState& panels, FrameStats& stats,
                                                const InputMapper& input) {
  std::optional<std::filesystem::path> toLoad;
  sim::World& world = session.world();

  // Metrics for the plots, every frame.
  const sim::StrainStats strain = sim::structuralStrain(world);
  panels.maxStrain.add(static_cast<float>(strain.max * 100.0));
  panels.meanStrain.add(static_cast<float>(strain.mean * 100.0));
  panels.energy.add(static_cast<float>(sim::energy(world).total()));
  if (++panels.framesSinceCount >= PanelState::kIntersectionFrames) {
    panels.framesSinceCount = 0;
    panels.intersections = sim::countIntersections(world).pairs;
  }
  panels.intersectionHistory.add(static_cast<float>(panels.intersections));
  if (panels.stages.size() != world.profile().size()) {
    panels.stages.assign(world.profile().size(), History{});
    panels.stageNames.clear();
    for (const sim::StageTiming& timing : world.profile()) panels.stageNames.emplace_back(sim::name(timing.stage));
  }
  for (std::size_t i = 0; i < world.profile().size(); ++i) {
    panels.stages[i].add(static_cast<float>(world.profile()[i].lastSeconds * 1e3));
  }

  hud(session, panels, stats);
  if (panels.showHelp) help();
  if (!panels.showPanels) return toLoad;

  const ImVec2 display = ImGui::GetIO().DisplaySize;
  // On the right, a third of the window at most; collapsed at first on a small window.
  const float width = std::min(360.0f, display.x * 0.34f);
  ImGui::SetNextWindowPos(ImVec2(display.x - width - 10.0f, 10.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(width, display.y - 20.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowCollapsed(display.x < 800.0f, ImGuiCond_FirstUseEver);
  ImGui::Begin("Drape");

  if (ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
    static std::vector<std::filesystem::path> scenes = shippedScenes();
    const std::string current = session.path().stem().string();
    if (ImGui::BeginCombo("scene", current.c_str())) {
      for (const std::filesystem::path& file : scenes) {
        if (ImGui::Selectable(file.stem().string().c_str(), file.stem().string() == current)) toLoad = file;
      }
      ImGui::EndCombo();
    }
    if (ImGui::Button(session.paused ? "run" : "pause")) session.paused = !session.paused;
    ImGui::SameLine();
    if (ImGui::Button("step") && session.paused) session.step();
    ImGui::SameLine();
    if (ImGui::Button("reset")) {
      session.reset();  // a new world: nothing below may use the old one
      ImGui::End();
      return toLoad;
    }
    ImGui::SameLine();
    if (ImGui::Button("undo")) session.undo();
    ImGui::SameLine();
    if (ImGui::Button("screenshot")) panels.wantScreenshot = true;
    // Every sheet made of a fabric in physical units (docs/fabric.md), or as the scene says.
    const std::string fabric = session.fabric().empty() ? "as the scene says" : session.fabric();
    if (ImGui::BeginCombo("fabric", fabric.c_str())) {
      std::optional<std::optional<std::string>> chosen;
      if (ImGui::Selectable("as the scene says", session.fabric().empty())) chosen.emplace(std::nullopt);
      for (const scene::FabricPreset& preset : scene::fabricPresets()) {
        const std::string name(preset.name);
        if (ImGui::Selectable(name.c_str(), name == session.fabric())) chosen.emplace(name);
        if (ImGui::IsItemHovered()) {
          ImGui::SetTooltip("%.0f g/m^2, bending rigidity %.2g N m, bending length %.1f mm\n%s",
                            1000.0 * preset.fabric.arealDensity, preset.fabric.bendingRigidity,
                            1000.0 * std::cbrt(preset.fabric.bendingRigidity / (preset.fabric.arealDensity * 9.81)),
                            std::string(preset.source).c_str());
        }
      }
      ImGui::EndCombo();
      if (chosen) {
        session.setFabric(*chosen);  // a new world: nothing below may use the old one
        ImGui::End();
        return toLoad;
      }
    }
    char file[256];
    std::snprintf(file, sizeof file, "%s", panels.file.c_str());
    if (ImGui::InputText("file", file, sizeof file)) panels.file = file;
    if (ImGui::Button("save")) applyKey(KeyAction::save, session, panels);
    ImGui::SameLine();
    if (ImGui::Button("load")) toLoad = panels.file;
  }

  interact::Interaction& interaction = session.interaction();
  if (ImGui::CollapsingHeader("Hands", ImGuiTreeNodeFlags_DefaultOpen)) {
    for (interact::Mode mode : {interact::Mode::sticky, interact::Mode::cut, interact::Mode::create}) {
      if (ImGui::RadioButton(std::string(interact::name(mode)).c_str(), interaction.mode() == mode)) {
        interaction.setMode(mode);
      }
      ImGui::SameLine();
    }
    ImGui::NewLine();
    for (interact::FingerPlane plane : {interact::FingerPlane::table, interact::FingerPlane::view}) {
      const std::string label = std::string(interact::name(plane)) + " plane";
      if (ImGui::RadioButton(label.c_str(), interaction.settings().plane == plane)) interaction.setPlane(plane);
      ImGui::SameLine();
    }
    ImGui::NewLine();
    interact::InteractionSettings& hands = interaction.settings();
    sliderReal("finger radius (m)", hands.radius, 0.005, 0.3);
    sliderReal("pinch distance (m)", hands.pinchDistance, 0.0, 0.5);
    sliderReal("pinch height (m)", hands.pinchHeight, 0.0, 1.0);
    sliderReal("lift speed (m/s)", hands.liftSpeed, 0.05, 5.0);
    sliderReal("drawn spacing (m)", hands.spacing, 0.01, 0.2);
    ImGui::Text("touches %d, parked mouse fingers %d", input.touchesDown(), input.parkedFingers());
  }

  sim::WorldSettings tuned = world.settings();
  bool changed = false;
  if (ImGui::CollapsingHeader("Solver", ImGuiTreeNodeFlags_DefaultOpen)) {
    // Model and integrator restart the scene (materials mean different things in the two models).
    int model = tuned.solver.model == sim::Model::position ? 0 : 1;
    const char* models[] = {"position (Verlet + constraints)", "force (springs)"};
    int integrator = static_cast<int>(tuned.solver.integrator);
    const char* integrators[] = {"explicit Euler", "symplectic Euler", "Verlet", "midpoint", "RK4"};
    bool restart = ImGui::Combo("model", &model, models, 2);
    if (model == 1) restart |= ImGui::Combo("integrator", &integrator, integrators, 5);
    if (restart) {
      session.setModel(model == 0 ? sim::Model::position : sim::Model::force, static_cast<sim::Integrator>(integrator));
      ImGui::End();
      return toLoad;
    }
    changed |= sliderReal("dt (s)", tuned.solver.dt, 0.001, 0.05, "%.4f", ImGuiSliderFlags_Logarithmic);
    // The force model may have taken hundreds to stay stable (scene::withModel): the slider reaches them.
    changed |= ImGui::SliderInt("substeps", &tuned.solver.substeps, 1, std::max(32, world.settings().solver.substeps));
    changed |= ImGui::SliderInt("iterations", &tuned.solver.iterations, 0, 100);
    changed |= sliderReal("damping (1/s)", tuned.solver.damping, 0.0, 5.0);
    if (tuned.solver.model == sim::Model::position) {
      changed |= ImGui::Checkbox("XPBD", &tuned.solver.xpbd);
      ImGui::SameLine();
      changed |= ImGui::Checkbox("tethers", &tuned.solver.tethers);
      ImGui::SameLine();
      changed |= ImGui::Checkbox("lines", &tuned.solver.lines);
      // On a line of its own: the row above is full.
      if (tuned.solver.lines) changed |= ImGui::Checkbox("geometric stiffness", &tuned.solver.geometricStiffness);
      // Each on a line of its own: two do not fit side by side.
      if (tuned.solver.lines && tuned.solver.tethers) {
        changed |= ImGui::Checkbox("tethers between line steps", &tuned.solver.tethersBetweenSteps);
      }
      if (tuned.solver.lines) {
        changed |= ImGui::SliderInt("extra steps", &tuned.solver.extraLineSteps, 0, 8);
        if (tuned.solver.extraLineSteps > 0) {
          changed |= sliderReal("max stretch", tuned.solver.stretchTolerance, 0.0, 0.2, "%.3f");
        }
      }
    }
    int threads = session.threads();
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (ImGui::SliderInt("threads", &threads, 1, std::max(cores, 2))) session.setThreads(threads);
    changed |= ImGui::Checkbox("tearing", &tuned.tearing.enabled);
    changed |= sliderReal("tear at (x rest)", tuned.tearing.threshold, 1.01, 5.0);
  }
  if (ImGui::CollapsingHeader("World")) {
    changed |= vector3("gravity (m/s^2)", tuned.gravity, 0.05f);
    changed |= vector3("wind (m/s)", tuned.air.velocity, 0.05f);
    changed |= sliderReal("drag (1/s)", tuned.air.drag, 0.0, 5.0);
    changed |= sliderReal("wind pressure", tuned.air.pressure, 0.0, 20.0);
    for (std::size_t i = 0; i < tuned.colliders.size(); ++i) {
      ImGui::PushID(static_cast<int>(i));
      sim::Friction& f = tuned.colliders[i].friction;
      ImGui::Text("collider %zu", i);
      changed |= sliderReal("static friction", f.staticCoefficient, 0.0, 2.0);
      changed |= sliderReal("kinetic friction", f.kineticCoefficient, 0.0, 2.0);
      ImGui::PopID();
    }
    if (tuned.solver.model == sim::Model::position) {
      changed |= ImGui::Checkbox("self-collision", &tuned.selfCollision.enabled);
      changed |= sliderReal("self distance (m)", tuned.selfCollision.distance, 0.001, 0.1);
    }
  }
  if (changed) session.tune(tuned);

  if (ImGui::CollapsingHeader("View")) {
    ImGui::Checkbox("strain colours", &panels.frameOptions.strainMap);
    ImGui::Checkbox("pins", &panels.frameOptions.showPins);
    ImGui::Checkbox("antialiasing (4x MSAA)", &panels.frameOptions.multisample);
    ImGui::SliderInt("shadow softness", &panels.frameOptions.shadowSoftness, 0, 3);
    ImGui::SliderInt("shadow map", &panels.frameOptions.shadowMapSize, 256, 4096);
  }

  if (ImGui::CollapsingHeader("Plots", ImGuiTreeNodeFlags_DefaultOpen)) {
    std::size_t particles = 0, constraints = 0, torn = 0, pieces = 0;
    for (const sim::Cloth& cloth : world.cloths()) {
      particles += cloth.state.position.size();
      for (const auto& list : cloth.rest.constraints) constraints += list.size();
      torn += cloth.topology.torn;
      pieces += cloth.pieceCount;
    }
    ImGui::Text("particles %zu   constraints %zu   torn %zu", particles, constraints, torn);
    ImGui::Text("cloths %zu   pieces %zu   fingers %zu   %.0f fps", world.cloths().size(), pieces,
                world.fingers().size(), stats.fps.latest());
    ImGui::Text("intersecting triangle pairs %zu", panels.intersections);
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip(
          "Pairs of triangles passing through each other (cloth through cloth), counted exactly every %d "
          "frames; 0 when no cloth passes through itself or another",
          PanelState::kIntersectionFrames);
    }
    const ImVec2 plot(0.0f, 40.0f);
    char overlay[64];
    std::snprintf(overlay, sizeof overlay, "step %.2f ms/frame", stats.stepMilliseconds.latest());
    ImGui::PlotLines("##step", stats.stepMilliseconds.data(), History::kLength, stats.stepMilliseconds.offset(),
                     overlay, 0.0f, std::max(1.0f, stats.stepMilliseconds.largest()), plot);
    for (std::size_t i = 0; i < panels.stages.size(); ++i) {
      std::snprintf(overlay, sizeof overlay, "%s %.2f ms", panels.stageNames[i].c_str(), panels.stages[i].latest());
      ImGui::PlotLines(("##stage" + std::to_string(i)).c_str(), panels.stages[i].data(), History::kLength,
                       panels.stages[i].offset(), overlay, 0.0f, std::max(0.5f, panels.stages[i].largest()),
                       ImVec2(0.0f, 24.0f));
    }
    std::snprintf(overlay, sizeof overlay, "max strain %.2f %%", panels.maxStrain.latest());
    ImGui::PlotLines("##max", panels.maxStrain.data(), History::kLength, panels.maxStrain.offset(), overlay, 0.0f,
                     std::max(1.0f, panels.maxStrain.largest()), plot);
    std::snprintf(overlay, sizeof overlay, "mean strain %.3f %%", panels.meanStrain.latest());
    ImGui::PlotLines("##mean", panels.meanStrain.data(), History::kLength, panels.meanStrain.offset(), overlay, 0.0f,
                     std::max(0.1f, panels.meanStrain.largest()), plot);
    std::snprintf(overlay, sizeof overlay, "intersecting triangle pairs %zu", panels.intersections);
    ImGui::PlotLines("##intersections", panels.intersectionHistory.data(), History::kLength,
                     panels.intersectionHistory.offset(), overlay, 0.0f,
                     std::max(1.0f, panels.intersectionHistory.largest()), plot);
    std::snprintf(overlay, sizeof overlay, "energy %.3g J", panels.energy.latest());
    ImGui::PlotLines("##energy", panels.energy.data(), History::kLength, panels.energy.offset(), overlay, FLT_MAX,
                     FLT_MAX, plot);
  }
  ImGui::End();
  return toLoad;
}

render::Overlay fingerOverlay(Session& session) {
  render::Overlay overlay;
  const interact::Interaction& interaction = session.interaction();
  for (const interact::TouchView& touch : interaction.touches()) {
    if (touch.mode == interact::Mode::sticky) {
      const glm::vec4 colour = touch.pinched ? glm::vec4{1.0f, 0.85f, 0.2f, 1.0f} : glm::vec4{1.0f, 1.0f, 1.0f, 1.0f};
      overlay.addRing(touch.position, interaction.settings().radius, glm::dvec3{0.0, 1.0, 0.0}, colour);
    } else {
      overlay.addStroke(touch.stroke, touch.mode == interact::Mode::cut ? glm::vec4{0.95f, 0.15f, 0.1f, 1.0f}
                                                                        : glm::vec4{0.15f, 0.35f, 0.95f, 1.0f});
    }
  }
  return overlay;
}

}  // namespace drape::app
