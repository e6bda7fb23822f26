#include "panels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include <imgui.h>
#include <imgui_internal.h>  // ClosePopupsExceptModals: Esc closes an open list

#include "drape/scene/fabric.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::app {

namespace {

// Marks a stage's part among the plots' names (panels.stageNames).
constexpr std::string_view kPartMark = "  ";

const char* const kHelp[][2] = {
    {"touch", "a sticky finger (draws in Create mode, cuts in Cut mode); any number at once"},
    {"left drag", "a finger"},
    {"Shift + left drag", "a finger that stays down when the button is released"},
    {"wheel", "lift (or lower) the finger being dragged, else the last parked; with none, zoom"},
    {"Ctrl + left click", "lift the parked finger whose ring is nearest"},
    {"right drag / middle drag", "orbit / pan the camera"},
    {"F / Home", "frame the cloth / the view the scene starts with"},
    {"1 / 2 / 3", "Sticky / Cut / Create mode"},
    {"V", "fingers move in the table plane or the view plane"},
    {"W / C", "the triangles' edges / strain colours, on or off"},
    {"Space / N", "pause / one step while paused"},
    {"R", "reset the scene (the camera stays)"},
    {"U or Ctrl+Z", "undo the last drawn cloth, cut or tear"},
    {"Ctrl+Y or Ctrl+Shift+Z", "redo what undo took back"},
    {"P or F12", "screenshot (drape-screenshot-NNN.png)"},
    {"Ctrl+S / Ctrl+O", "save / load the file named in the panel"},
    {"Tab / H or F1", "hide the panels and the HUD (a clean view) / this help"},
    {"Esc twice or Ctrl+Q", "quit"},
};

struct ShippedScene {
  std::filesystem::path file;
  std::string name;
  std::string description;  // the file's "description", for the picker's tooltip
};

std::vector<ShippedScene> shippedScenes() {
  std::vector<ShippedScene> scenes;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(scene::sceneDirectory(), error)) {
    if (entry.path().extension() != ".json") continue;
    ShippedScene s{entry.path(), entry.path().stem().string(), {}};
    std::ifstream in(entry.path());
    const nlohmann::json document = nlohmann::json::parse(in, nullptr, false);
    if (document.is_object() && document.contains("description") && document["description"].is_string()) {
      s.description = document["description"].get<std::string>();
    }
    scenes.push_back(std::move(s));
  }
  std::sort(scenes.begin(), scenes.end(), [](const auto& a, const auto& b) { return a.file < b.file; });
  return scenes;
}

// A tooltip on the item just drawn, wrapped to a readable width.
void tip(const char* text) {
  if (!ImGui::IsItemHovered()) return;
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 28.0f);
  ImGui::TextUnformatted(text);
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

// Records the window being drawn (between Begin and End, or inside a combo's popup) as one the
// pointer can be over.
void noteWindow(PanelState& panels) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  if (display.x <= 0.0f || display.y <= 0.0f) return;
  const ImVec2 at = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  panels.windows.push_back(
      {at.x / display.x, at.y / display.y, (at.x + size.x) / display.x, (at.y + size.y) / display.y});
}

const char* modeHint(interact::Mode mode, bool small) {
  if (small) {
    switch (mode) {
      case interact::Mode::sticky: return "drag the cloth; right drag orbits";
      case interact::Mode::cut: return "swipe across the cloth to cut it";
      case interact::Mode::create: return "draw an outline on the table";
    }
  }
  switch (mode) {
    case interact::Mode::sticky:
      return "Sticky: drag the cloth with the left button or a finger (Shift leaves the finger down, the wheel "
             "lifts it); right drag orbits";
    case interact::Mode::cut: return "Cut: swipe across the cloth to cut it along the swipe";
    case interact::Mode::create: return "Create: draw an outline on the table; a cloth of that shape appears";
  }
  return "";
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
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  // No wider than the window leaves beside the panel, and never half of it: long lines wrap.
  const float room = std::max(120.0f, std::min(display.x * 0.5f, display.x - panels.panelWidth - 30.0f));
  // Under the collapsed panel's title bar where they would meet (a small window: at 320 x 240 the
  // title lay across the HUD's first lines).
  float top = 10.0f;
  // (The panel is collapsed, whenever the HUD is drawn, where it leaves no width.)
  if (panels.panelWidth == 0.0f && panels.panelRect[0] < 10.0f + room) {
    top = std::max(top, panels.panelRect[1] + panels.panelRect[3] + 4.0f);
  }
  ImGui::SetNextWindowPos(ImVec2(10, top));
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), ImVec2(room, display.y * 0.6f));
  ImGui::Begin("HUD", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs);
  ImGui::PushTextWrapPos(room - 16.0f);
  const interact::Interaction& interaction = session.interaction();
  const double fps = stats.frameSeconds > 0.0 ? 1.0 / stats.frameSeconds : 0.0;
  ImGui::Text("%s   %.0f fps   t = %.2f s%s", session.scene().name.c_str(), fps, session.world().time(),
              session.paused ? "   PAUSED" : "");
  // First what the mode does and the keys of the first minute (a small window shows only these,
  // shorter, the status, and what is being drawn), then the detail.
  const bool small = display.x < 640.0f || display.y < 420.0f;
  ImGui::TextColored(ImVec4(0.7f, 0.9f, 1.0f, 1.0f), "%s", modeHint(interaction.mode(), small));
  ImGui::TextColored(ImVec4(0.85f, 0.85f, 0.85f, 1.0f),
                     "1 sticky  2 cut  3 create   F frame   Home view   F1 all keys");
  for (const interact::TouchView& touch : interaction.touches()) {
    if (touch.mode != interact::Mode::create) continue;
    const OutlineSize size = outlineSize(touch.stroke, interaction.settings().spacing);
    ImGui::Text("outline %.2f m x %.2f m: about %.0f particles at %.0f mm", size.width, size.depth, size.particles,
                1000.0 * interaction.settings().spacing);
  }
  if (!session.status.empty()) ImGui::TextWrapped("%s", session.status.c_str());
  if (small) {
    ImGui::PopTextWrapPos();
    ImGui::End();
    return;
  }
  ImGui::Text("mode: %s (%s plane)   fingers: %zu", std::string(interact::name(interaction.mode())).c_str(),
              std::string(interact::name(interaction.settings().plane)).c_str(), session.world().fingers().size());
  ImGui::Text("simulation %.1f ms (%d steps), drawing %.1f ms per frame", stats.simulationSeconds * 1e3, stats.steps,
              stats.drawSeconds * 1e3);
  if (display.x >= 1000.0f) {  // the detail, where there is room for it (the parts of the same frame)
    ImGui::Text("  drawing: scene %.1f ms (at %.0f %% of the window%s), panels %.1f ms, presenting %.1f ms",
                stats.sceneSeconds * 1e3, panels.renderScale.scale() * 100.0,
                panels.renderScale.automatic() ? ", auto" : "", stats.panelSeconds * 1e3, stats.swapSeconds * 1e3);
  }
  if (fps > 0.0 && fps < 55.0) {
    // Say why, in the terms the user can act on.
    const bool simulation = stats.simulationSeconds > stats.drawSeconds;
    ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "below 60 fps: %s takes most of each frame%s",
                       simulation ? "the simulation" : "drawing (software GL)",
                       simulation ? " (fewer iterations or substeps, or a smaller cloth)" : "");
  }
  if (stats.fellBehind) ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "slower than real time");
  ImGui::PopTextWrapPos();
  ImGui::End();
}

// The strain colours' legend, at the bottom left while they are on: the bar from rest to the
// scale the View panel sets, read in per cent of a link's rest length.
void strainLegend(PanelState& panels) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float scale = panels.frameOptions.strainScale;
  ImGui::SetNextWindowPos(ImVec2(10.0f, display.y - 10.0f), ImGuiCond_Always, ImVec2(0.0f, 1.0f));
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("Strain", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav);
  noteWindow(panels);
  ImGui::Text("stretch of the longest link at each particle");
  const float width = std::min(260.0f, std::max(120.0f, display.x * 0.25f)), height = 14.0f;
  const ImVec2 at = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  constexpr int kSteps = 32;
  for (int i = 0; i < kSteps; ++i) {
    const auto colour = [&](int k) {
      const glm::vec3 c = render::strainColour(scale * static_cast<float>(k) / kSteps, scale);
      return ImGui::GetColorU32(ImVec4(c.r, c.g, c.b, 1.0f));
    };
    const float x0 = at.x + width * static_cast<float>(i) / kSteps,
                x1 = at.x + width * static_cast<float>(i + 1) / kSteps;
    draw->AddRectFilledMultiColor(ImVec2(x0, at.y), ImVec2(x1, at.y + height), colour(i), colour(i + 1), colour(i + 1),
                                  colour(i));
  }
  ImGui::Dummy(ImVec2(width, height));
  ImGui::Text("0 %%");
  char label[32];
  std::snprintf(label, sizeof label, "%.3g %%", scale * 50.0);
  ImGui::SameLine(width * 0.5f - ImGui::CalcTextSize(label).x * 0.5f + ImGui::GetStyle().WindowPadding.x);
  ImGui::TextUnformatted(label);
  std::snprintf(label, sizeof label, "%.3g %% and more", scale * 100.0);
  ImGui::SameLine(std::max(width - ImGui::CalcTextSize(label).x + ImGui::GetStyle().WindowPadding.x, 0.0f));
  ImGui::TextUnformatted(label);
  ImGui::End();
}

void help(PanelState& panels) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(display.x * 0.5f, display.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  // On a small window it keeps inside it: the descriptions wrap, and it scrolls.
  const float width = std::min(display.x - 20.0f, ImGui::GetFontSize() * 52.0f);
  ImGui::SetNextWindowSize(ImVec2(std::max(width, 100.0f), 0.0f), ImGuiCond_Always);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f),
                                      ImVec2(display.x - 20.0f, std::max(display.y - 20.0f, 60.0f)));
  ImGui::Begin("Help", nullptr, ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoResize);
  noteWindow(panels);
  if (ImGui::BeginTable("bindings", 2, ImGuiTableFlags_SizingStretchProp)) {
    for (const auto& row : kHelp) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(row[0]);
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", row[1]);
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
    case KeyAction::redo: session.redo(); break;
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
    case KeyAction::frame: session.frameCloths(); break;
    case KeyAction::resetView: session.resetView(); break;
    case KeyAction::edges: panels.frameOptions.wireframe = !panels.frameOptions.wireframe; break;
    case KeyAction::strain: panels.frameOptions.strainMap = !panels.frameOptions.strainMap; break;
    case KeyAction::step: session.paused = true; break;  // the app takes the step
    case KeyAction::none:
    case KeyAction::screenshot:
    case KeyAction::askQuit:
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
  // Each stage, then its parts (indented), as they ran in the last step.
  std::vector<std::string> names;
  std::vector<double> seconds;
  for (const sim::StageTiming& timing : world.profile()) {
    names.emplace_back(sim::name(timing.stage));
    seconds.push_back(timing.lastSeconds);
    for (const sim::StageTiming& part : timing.parts) {
      names.push_back(std::string(kPartMark) + std::string(sim::name(part.stage)));
      seconds.push_back(part.lastSeconds);
    }
  }
  if (names != panels.stageNames) {
    panels.stages.assign(names.size(), History{});
    panels.stageNames = std::move(names);
  }
  for (std::size_t i = 0; i < seconds.size(); ++i) panels.stages[i].add(static_cast<float>(seconds[i] * 1e3));

  panels.windows.clear();
  if (panels.closePopups) {  // Esc with a list open closes the list (and does not count towards quitting)
    ImGui::ClosePopupsExceptModals();
    panels.closePopups = false;
  }
  if (!panels.showPanels) {  // Tab: a clean view of the scene, no HUD, no panel
    panels.panelWidth = 0.0f;
    panels.hiddenRight = 0.0f;
    panels.panelDrawList = nullptr;
    if (panels.showHelp) help(panels);
    return toLoad;
  }
  hud(session, panels, stats);
  if (panels.showHelp) help(panels);
  if (panels.frameOptions.strainMap) strainLegend(panels);

  const ImVec2 display = ImGui::GetIO().DisplaySize;
  // Anchored to the right edge, full height, 30 % of the window wide (230 to 380 points) and
  // placed again whenever the window's size changes; collapsed on a window too small to hold it.
  const bool resized = display.x != panels.lastDisplayWidth || display.y != panels.lastDisplayHeight;
  const bool first = panels.lastDisplayWidth < 0.0f;
  panels.lastDisplayWidth = display.x;
  panels.lastDisplayHeight = display.y;
  const float width = std::clamp(display.x * 0.3f, std::min(230.0f, display.x - 20.0f), 380.0f);
  if (resized) {
    ImGui::SetNextWindowPos(ImVec2(std::max(0.0f, display.x - width - 10.0f), 10.0f), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(std::max(1.0f, width), std::max(1.0f, display.y - 20.0f)), ImGuiCond_Always);
    // Collapsed while the window is too small to hold it, and opened again when it grows back,
    // unless the user collapsed it by hand.
    const bool small = display.x < 500.0f || display.y < 300.0f;
    if (first || small || panels.collapsedBySize) {
      ImGui::SetNextWindowCollapsed(small, ImGuiCond_Always);
      panels.collapsedBySize = small;
    }
  }
  ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: the scene behind it is not drawn
  ImGui::Begin("Drape");
  noteWindow(panels);
  panels.panelWidth = ImGui::IsWindowCollapsed() ? 0.0f : ImGui::GetWindowSize().x + 10.0f;
  {
    const ImVec2 at = ImGui::GetWindowPos(), extent = ImGui::GetWindowSize();
    constexpr float kSlack = 12.0f;  // the margin it is placed with, and a little more
    const bool againstTheEdge = at.x + extent.x >= display.x - kSlack && at.y <= kSlack &&
                                at.y + extent.y >= display.y - kSlack && at.x >= 0.0f;
    panels.hiddenRight = !ImGui::IsWindowCollapsed() && againstTheEdge ? display.x - at.x : 0.0f;
    panels.panelDrawList = ImGui::IsWindowCollapsed() ? nullptr : ImGui::GetWindowDrawList();
    panels.panelRect[0] = at.x;
    panels.panelRect[1] = at.y;
    panels.panelRect[2] = extent.x;
    panels.panelRect[3] = extent.y;
  }
  // Widgets leave room on their right for the longest label, and keep at least 64 points
  // themselves: on a narrow panel (an 800-point window) the labels were cut off at 42 % of it.
  ImGui::PushItemWidth(-std::max(
      std::min(ImGui::CalcTextSize("pinch distance (m) ").x, ImGui::GetContentRegionAvail().x - 64.0f), 0.0f));
  // A button beside the last item only where the panel has room for it (else on the next line):
  // on a narrow panel "redo" was cut to "re".
  const auto besideIfRoom = [](const char* label) {
    const ImGuiStyle& style = ImGui::GetStyle();
    if (ImGui::GetItemRectMax().x + style.ItemSpacing.x + ImGui::CalcTextSize(label).x + 2.0f * style.FramePadding.x <
        ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) {
      ImGui::SameLine();
    }
  };

  // The snapshot opened is the file Ctrl+S writes, while it is open: another scene chosen puts the
  // field back, so that a save does not put that scene over the snapshot.
  if (session.path() != panels.fileFrom) {
    if (scene::isSnapshotName(session.path())) {
      panels.file = session.path().string();
      panels.fileFrom = session.path();
    } else if (!panels.fileFrom.empty()) {
      panels.file = PanelState{}.file;
      panels.fileFrom.clear();
    }
  }
  if (ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
    static const std::vector<ShippedScene> scenes = shippedScenes();
    // A snapshot by its file's name (its scene's name is in the HUD's first line).
    const std::string current =
        scene::isSnapshotName(session.path()) ? session.path().filename().string() : session.path().stem().string();
    if (ImGui::BeginCombo("scene", current.c_str())) {
      noteWindow(panels);
      for (const ShippedScene& shipped : scenes) {
        if (ImGui::Selectable(shipped.name.c_str(), shipped.name == current)) toLoad = shipped.file;
        if (!shipped.description.empty()) tip(shipped.description.c_str());
      }
      ImGui::EndCombo();
    }
    if (!session.scene().description.empty()) {
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("%s", session.scene().description.c_str());
      ImGui::PopTextWrapPos();
    }
    if (ImGui::Button(session.paused ? "run" : "pause")) session.paused = !session.paused;
    besideIfRoom("step");
    if (ImGui::Button("step")) {
      // While running, a step pauses first: one step, then still.
      session.paused = true;
      session.step();
    }
    tip("one step (pauses first while running; N or . does the same)");
    besideIfRoom("reset");
    if (ImGui::Button("reset")) {
      session.reset();  // a new world: nothing below may use the old one
      ImGui::PopItemWidth();
      ImGui::End();
      return toLoad;
    }
    besideIfRoom("undo");
    if (ImGui::Button("undo")) session.undo();
    besideIfRoom("redo");
    if (ImGui::Button("redo")) session.redo();
    besideIfRoom("screenshot");
    if (ImGui::Button("screenshot")) panels.wantScreenshot = true;
    // Every sheet made of a fabric in physical units (docs/fabric.md), or as the scene says.
    const std::string fabric = session.fabric().empty() ? "as the scene says" : session.fabric();
    if (ImGui::BeginCombo("fabric", fabric.c_str())) {
      noteWindow(panels);
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
        ImGui::PopItemWidth();
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
    ImGui::TextWrapped("touches %d, parked mouse fingers %d", input.touchesDown(), input.parkedFingers());
  }

  sim::WorldSettings tuned = world.settings();
  bool changed = false;
  if (ImGui::CollapsingHeader("Solver")) {
    // Model and integrator restart the scene (materials mean different things in the two models).
    int model = tuned.solver.model == sim::Model::position ? 0 : 1;
    const char* models[] = {"position", "force (springs)"};
    int integrator = static_cast<int>(tuned.solver.integrator);
    const char* integrators[] = {"explicit Euler", "symplectic Euler", "Verlet", "midpoint", "RK4"};
    bool restart = ImGui::Combo("model", &model, models, 2);
    tip("position: Verlet with constraints projected each substep (the seed's model); force: mass-spring forces "
        "and an integrator. Changing it restarts the scene with that model's materials");
    if (model == 1) restart |= ImGui::Combo("integrator", &integrator, integrators, 5);
    if (restart) {
      session.setModel(model == 0 ? sim::Model::position : sim::Model::force, static_cast<sim::Integrator>(integrator));
      ImGui::PopItemWidth();
      ImGui::End();
      return toLoad;
    }
    changed |= sliderReal("dt (s)", tuned.solver.dt, 0.001, 0.05, "%.4f", ImGuiSliderFlags_Logarithmic);
    // The force model may have taken hundreds to stay stable (scene::withModel): the slider reaches them.
    changed |= ImGui::SliderInt("substeps", &tuned.solver.substeps, 1, std::max(32, world.settings().solver.substeps));
    if (world.substeps() != world.settings().solver.substeps) {
      ImGui::TextDisabled("running %d for the fabric's fine cells", world.substeps());
      char why[256];
      std::snprintf(why, sizeof why,
                    "solver.fabricSubstepSpeed: a world with a fabric cloth takes substeps no longer than its finest "
                    "fabric's spacing / %g m/s, so that it bends as its fabric does at any spacing (docs/fabric.md)",
                    static_cast<double>(world.settings().solver.fabricSubstepSpeed));
      tip(why);
    }
    // The force model has no constraint sweeps: its iterations would do nothing.
    if (tuned.solver.model == sim::Model::position) {
      changed |= ImGui::SliderInt("iterations", &tuned.solver.iterations, 0, 100);
      tip("constraint sweeps a substep: more is stiffer and costs more");
    }
    changed |= sliderReal("damping (1/s)", tuned.solver.damping, 0.0, 5.0);
    if (tuned.solver.model == sim::Model::position) {
      changed |= ImGui::Checkbox("XPBD", &tuned.solver.xpbd);
      tip("extended position-based dynamics: stiffness means the same whatever the iterations and substeps");
      ImGui::SameLine();
      changed |= ImGui::Checkbox("tethers", &tuned.solver.tethers);
      tip("long-range limits from every pinned particle: a hanging cloth cannot stretch past its length");
      // On a line of its own: the row above is full.
      int stretchSolver = static_cast<int>(tuned.solver.stretchSolver);
      if (ImGui::Combo("stretch solver", &stretchSolver, "gauss-seidel\0lines\0")) {
        tuned.solver.stretchSolver = static_cast<sim::StretchSolver>(stretchSolver);
        changed = true;
      }
      tip("gauss-seidel: the seed's sweep, link by link; lines: each lattice line's stretch solved exactly at "
          "once (the fast sweep)");
      if (tuned.solver.lines() && !tuned.solver.xpbd) {
        bool target = tuned.solver.maxStretch > 0.0;
        if (ImGui::Checkbox("work to a max stretch", &target)) {
          tuned.solver.maxStretch = target ? 0.04 : 0.0;
          changed = true;
        }
        tip("the line solve takes what it needs (geometric stiffness on taut lines, tethers between its steps, "
            "up to 4 more steps) while a link is longer than this");
        if (target) changed |= sliderReal("max stretch", tuned.solver.maxStretch, 0.001, 0.2, "%.3f");
      }
    }
    int threads = session.threads();
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (ImGui::SliderInt("threads", &threads, 1, std::max(cores, 2))) session.setThreads(threads);
    changed |= ImGui::Checkbox("tearing", &tuned.tearing.enabled);
    changed |= sliderReal("tear at (x rest)", tuned.tearing.threshold, 1.01, 5.0);
    tip("a link tears when stretched to this many times its rest length");
  }
  if (ImGui::CollapsingHeader("World")) {
    changed |= vector3("gravity (m/s^2)", tuned.gravity, 0.05f);
    changed |= vector3("wind (m/s)", tuned.air.velocity, 0.05f);
    changed |= sliderReal("drag (1/s)", tuned.air.drag, 0.0, 5.0);
    changed |= sliderReal("wind pressure", tuned.air.pressure, 0.0, 20.0);
    tip("kg/(m^2 s): the wind pushing on each triangle by how squarely it faces it (a sail's push); "
        "drag acts on every particle alike");
    for (std::size_t i = 0; i < tuned.colliders.size(); ++i) {
      ImGui::PushID(static_cast<int>(i));
      sim::Friction& f = tuned.colliders[i].friction;
      const sim::ColliderShape shape = tuned.colliders[i].shape;
      ImGui::Text("collider %zu: %s", i,
                  shape == sim::ColliderShape::plane     ? "the table (a plane)"
                  : shape == sim::ColliderShape::sphere  ? "a ball"
                  : shape == sim::ColliderShape::box     ? "a box"
                  : shape == sim::ColliderShape::capsule ? "a capsule"
                                                         : "a mesh");
      changed |= sliderReal("static friction", f.staticCoefficient, 0.0, 2.0);
      changed |= sliderReal("kinetic friction", f.kineticCoefficient, 0.0, 2.0);
      ImGui::PopID();
    }
    if (tuned.solver.model == sim::Model::position) {
      changed |= ImGui::Checkbox("self-collision", &tuned.selfCollision.enabled);
      tip("cloth never passes through itself or another cloth (docs/self-contact.md)");
      int method = tuned.selfCollision.method == sim::SelfContactMethod::triangles ? 0 : 1;
      const char* methods[] = {"triangles", "particles"};
      if (ImGui::Combo("self method", &method, methods, 2)) {
        tuned.selfCollision.method =
            method == 0 ? sim::SelfContactMethod::triangles : sim::SelfContactMethod::particles;
        changed = true;
      }
      tip("triangles: surfaces keep the distance apart, and an exact fail-safe keeps any step from passing one "
          "through another; particles: the first wave's method, particles kept apart (cheaper, but a triangle "
          "passes between particles unless the distance is about the particle spacing)");
      changed |= sliderReal("self distance (m)", tuned.selfCollision.distance, 0.001, 0.1);
      tip("how far apart two layers of cloth are kept");
    }
  }
  if (changed) {
    // A key switched off takes the keys that need it with it (back to gauss-seidel, or XPBD ticked:
    // the stretch target): the engine's one rule for it.
    tuned.solver = sim::consistent(tuned.solver);
    session.tune(tuned);
  }

  if (ImGui::CollapsingHeader("View")) {
    ImGui::Checkbox("woven", &panels.frameOptions.woven);
    tip("a gingham check and a plain weave printed on the cloth: they stretch and shear with it");
    ImGui::SameLine();
    ImGui::Checkbox("edges", &panels.frameOptions.wireframe);
    tip("the triangles' edges over the surface (W)");
    ImGui::SameLine();
    ImGui::Checkbox("particles", &panels.frameOptions.particles);
    tip("every particle as a dot");
    ImGui::Checkbox("strain colours", &panels.frameOptions.strainMap);
    tip("colour by stretch: each particle shows its longest structural link's strain (C)");
    if (panels.frameOptions.strainMap) {
      float percent = panels.frameOptions.strainScale * 100.0f;
      if (ImGui::SliderFloat("red at (%)", &percent, 0.5f, 100.0f, "%.1f", ImGuiSliderFlags_Logarithmic)) {
        panels.frameOptions.strainScale = std::clamp(percent, 0.5f, 100.0f) / 100.0f;
      }
      tip("the stretch shown fully red; the legend at the bottom left reads the colours");
    }
    ImGui::Checkbox("pins", &panels.frameOptions.showPins);
    ImGui::Checkbox("FXAA", &panels.frameOptions.fxaa);
    tip("cheap antialiasing: one filter pass over the picture that softens the cloth's stair-stepped edges");
    ImGui::SameLine();
    ImGui::Checkbox("4x MSAA", &panels.frameOptions.multisample);
    tip("true antialiasing, four samples a pixel: costly on a software renderer (replaces FXAA while on)");
    bool automatic = panels.renderScale.automatic();
    if (ImGui::Checkbox("auto resolution", &automatic)) panels.renderScale.setAutomatic(automatic);
    tip("draw the scene at as many pixels as keep 60 fps (down to half the window's width and height),\n"
        "stretched over the window; the panels stay sharp. A software renderer pays for every pixel");
    float scale = static_cast<float>(panels.renderScale.scale()) * 100.0f;
    if (ImGui::SliderFloat("resolution (%)", &scale, render::FrameOptions::kLowestRenderScale * 100.0f, 100.0f,
                           "%.0f")) {
      panels.renderScale.setAutomatic(false);
      panels.renderScale.set(scale / 100.0f);
    }
    tip("the scene's width and height in per cent of the window's; set by hand, auto resolution turns off");
    ImGui::SliderInt("shadow softness", &panels.frameOptions.shadowSoftness, 0, 3);
    ImGui::SliderInt("shadow map", &panels.frameOptions.shadowMapSize, 256, 4096);
  }

  if (ImGui::CollapsingHeader("Plots")) {
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
    if (world.hasStage(sim::Stage::selfContact)) {
      const sim::SelfContactStats contact = world.selfContactStats();
      ImGui::Text("self-contact pairs %lld   pushed %lld   zoned %lld", static_cast<long long>(contact.pairs),
                  static_cast<long long>(contact.pushed), static_cast<long long>(contact.zoned));
      tip("of the last substep: the vertex-triangle and edge-edge pairs near enough to meet, and those the "
          "contacts pushed apart; since the start: particles the fail-safe moved as one body with others "
          "to keep a step from passing cloth through cloth (docs/self-contact.md)");
    }
    const ImVec2 plot(0.0f, 40.0f);
    char overlay[64];
    std::snprintf(overlay, sizeof overlay, "step %.2f ms/frame", stats.stepMilliseconds.latest());
    ImGui::PlotLines("##step", stats.stepMilliseconds.data(), History::kLength, stats.stepMilliseconds.offset(),
                     overlay, 0.0f, std::max(1.0f, stats.stepMilliseconds.largest()), plot);
    for (std::size_t i = 0; i < panels.stages.size(); ++i) {
      // A stage's parts under it, indented and lower.
      const std::string& label = panels.stageNames[i];
      const bool part = label.starts_with(kPartMark);
      if (part) ImGui::Indent(24.0f);
      std::snprintf(overlay, sizeof overlay, "%s %.2f ms", label.c_str() + (part ? kPartMark.size() : 0),
                    panels.stages[i].latest());
      ImGui::PlotLines(("##stage" + std::to_string(i)).c_str(), panels.stages[i].data(), History::kLength,
                       panels.stages[i].offset(), overlay, 0.0f, std::max(0.5f, panels.stages[i].largest()),
                       ImVec2(0.0f, part ? 18.0f : 24.0f));
      if (part) ImGui::Unindent(24.0f);
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
  ImGui::PopItemWidth();
  ImGui::End();
  return toLoad;
}

OutlineSize outlineSize(const std::vector<glm::dvec3>& stroke, double spacing) {
  OutlineSize size;
  if (stroke.empty() || !(spacing > 0.0)) return size;
  glm::dvec2 lower{stroke.front().x, stroke.front().z}, upper = lower;
  double twiceArea = 0.0, perimeter = 0.0;
  for (std::size_t i = 0; i < stroke.size(); ++i) {
    const glm::dvec2 a{stroke[i].x, stroke[i].z};
    const glm::dvec2 b{stroke[(i + 1) % stroke.size()].x, stroke[(i + 1) % stroke.size()].z};
    lower = glm::min(lower, a);
    upper = glm::max(upper, a);
    twiceArea += a.x * b.y - b.x * a.y;
    perimeter += glm::length(b - a);
  }
  size.width = upper.x - lower.x;
  size.depth = upper.y - lower.y;
  size.particles = std::abs(twiceArea) / 2.0 / (spacing * spacing) + perimeter / spacing / 2.0 + 1.0;
  return size;
}

render::Overlay fingerOverlay(Session& session, const InputMapper& input) {
  render::Overlay overlay;
  // A cut just made: its path in red, fading out.
  for (const Session::Seam& seam : session.seams()) {
    const auto alpha = static_cast<float>(std::clamp(1.0 - seam.age / Session::kSeamSeconds, 0.0, 1.0));
    overlay.addStroke(seam.path, glm::vec4{0.95f, 0.15f, 0.1f, alpha});
  }
  const interact::Interaction& interaction = session.interaction();
  for (const interact::TouchView& touch : interaction.touches()) {
    if (touch.mode == interact::Mode::sticky) {
      const glm::vec4 colour = touch.pinched            ? glm::vec4{1.0f, 0.85f, 0.2f, 1.0f}
                               : input.parked(touch.id) ? glm::vec4{0.3f, 0.9f, 1.0f, 1.0f}
                                                        : glm::vec4{1.0f, 1.0f, 1.0f, 1.0f};
      overlay.addRing(touch.position, interaction.settings().radius, glm::dvec3{0.0, 1.0, 0.0}, colour);
      if (touch.position.y - touch.base.y > 1e-3) {
        // Lifted: a line down to where it would be on its plane, and a small ring there.
        overlay.lines.push_back({glm::vec3(touch.position), colour});
        overlay.lines.push_back({glm::vec3(touch.base), colour});
        overlay.addRing(touch.base, interaction.settings().radius * 0.4, glm::dvec3{0.0, 1.0, 0.0}, colour, 16);
      }
    } else {
      overlay.addStroke(touch.stroke, touch.mode == interact::Mode::cut ? glm::vec4{0.95f, 0.15f, 0.1f, 1.0f}
                                                                        : glm::vec4{0.15f, 0.35f, 0.95f, 1.0f});
    }
  }
  return overlay;
}

}  // namespace drape::app
