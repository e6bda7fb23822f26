#include "app.hpp"

#include <SDL.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <thread>

#include <backends/imgui_impl_opengl3.h>
#include <backends/imgui_impl_sdl.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include "drape/interact/replay.hpp"
#include "drape/render/layer.hpp"
#include "drape/render/renderer.hpp"
#include "drape/scene/error.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/output.hpp"
#include "drape/scene/snapshot.hpp"
#include "input.hpp"
#include "panels.hpp"
#include "png.hpp"
#include "session.hpp"

namespace drape::app {

namespace {

using Clock = std::chrono::steady_clock;

// What each frame cost, part by part, for --timings: medians, so a hiccup (a page fault, the X
// server) does not move them; the first frames (shaders compiled, the panel laid out) are left out.
struct TimingLog {
  static constexpr std::size_t kWarmUp = 30;
  std::vector<double> frame, simulation, steps, scene, scale, panels, swap;

  void add(double frameSeconds, const FrameStats& stats, double renderScale) {
    frame.push_back(frameSeconds * 1e3);
    scale.push_back(renderScale * 100.0);
    simulation.push_back(stats.simulationSeconds * 1e3);
    steps.push_back(stats.steps);
    scene.push_back(stats.sceneSeconds * 1e3);
    panels.push_back(stats.panelSeconds * 1e3);
    swap.push_back(stats.swapSeconds * 1e3);
  }
  static double median(std::vector<double> values) {
    values.erase(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(std::min(kWarmUp, values.size())));
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  }
  std::string summary(int width, int height) const {
    if (frame.size() <= kWarmUp) {
      return "timings: none: the first " + std::to_string(kWarmUp) +
             " frames are left out as warm-up and no frame came after them (run more, --exit-after " +
             std::to_string(kWarmUp + 1) + " or more)";
    }
    const double frameMs = median(frame);
    char line[320];
    std::snprintf(line, sizeof line,
                  "timings: %zu frames at %d x %d pixels, median ms: frame %.1f (%.0f fps), simulation %.1f (%.0f "
                  "steps), scene %.1f (at %.0f %% of the window), panels %.1f, swap %.1f",
                  frame.size() > kWarmUp ? frame.size() - kWarmUp : 0, width, height, frameMs,
                  frameMs > 0.0 ? 1e3 / frameMs : 0.0, median(simulation), median(steps), median(scene), median(scale),
                  median(panels), median(swap));
    return line;
  }
};

// What a draw list would put on the screen: its vertices, indices and commands, and the display
// they are drawn on. Two lists with the same key draw the same pixels.
std::uint64_t drawKey(const ImDrawList& list, const ImDrawData& data) {
  const auto bytes = [](const void* p, std::size_t n) {
    return std::hash<std::string_view>{}(std::string_view(static_cast<const char*>(p), n));
  };
  std::uint64_t key = bytes(list.VtxBuffer.Data, static_cast<std::size_t>(list.VtxBuffer.Size) * sizeof(ImDrawVert));
  const auto mix = [&key](std::uint64_t h) { key ^= h + 0x9e3779b97f4a7c15ULL + (key << 6) + (key >> 2); };
  mix(bytes(list.IdxBuffer.Data, static_cast<std::size_t>(list.IdxBuffer.Size) * sizeof(ImDrawIdx)));
  for (const ImDrawCmd& cmd : list.CmdBuffer) {
    const float clip[4] = {cmd.ClipRect.x, cmd.ClipRect.y, cmd.ClipRect.z, cmd.ClipRect.w};
    mix(bytes(clip, sizeof clip));
    mix(reinterpret_cast<std::uintptr_t>(cmd.TextureId));
    mix((static_cast<std::uint64_t>(cmd.ElemCount) << 32) ^ (static_cast<std::uint64_t>(cmd.IdxOffset) << 16) ^
        cmd.VtxOffset);
  }
  const float display[6] = {data.DisplayPos.x,  data.DisplayPos.y,       data.DisplaySize.x,
                            data.DisplaySize.y, data.FramebufferScale.x, data.FramebufferScale.y};
  mix(bytes(display, sizeof display));
  return key;
}

// Draws ImGui's lists, the main panel's from `layer`: drawn into it only when the panel's list
// changed (a hover, a value, a resize), and otherwise copied from it, which on llvmpipe costs a
// fraction of drawing its 300,000 blended pixels again. The panel is opaque and its rectangle is
// copied whole, so the lists before it (under it) and after it (over it) are drawn as ImGui would.
void drawImGui(ImDrawData* data, const PanelState& panels, render::Layer& layer, int pixelsWide, int pixelsHigh) {
  int panel = -1;
  for (int i = 0; i < data->CmdListsCount; ++i) {
    if (data->CmdLists[i] == panels.panelDrawList) panel = i;
  }
  if (panel < 0 || pixelsWide <= 0 || pixelsHigh <= 0) {
    layer.invalidate();
    ImGui_ImplOpenGL3_RenderDrawData(data);
    return;
  }
  const auto drawLists = [data](int first, int last) {
    if (last <= first) return;
    ImDrawData part = *data;
    part.CmdLists = data->CmdLists + first;
    part.CmdListsCount = last - first;
    ImGui_ImplOpenGL3_RenderDrawData(&part);
  };
  drawLists(0, panel);
  const std::uint64_t key = drawKey(*data->CmdLists[panel], *data);
  if (!layer.holds(key, pixelsWide, pixelsHigh)) {
    if (!layer.begin(key, pixelsWide, pixelsHigh)) {  // no layer here: drawn as ImGui would
      drawLists(panel, data->CmdListsCount);
      return;
    }
    drawLists(panel, panel + 1);
    layer.end();
  }
  // The panel's rectangle in pixels from the bottom left, rounded outwards.
  const float sx = data->FramebufferScale.x, sy = data->FramebufferScale.y;
  const int x0 = static_cast<int>(std::floor((panels.panelRect[0] - data->DisplayPos.x) * sx));
  const int x1 = static_cast<int>(std::ceil((panels.panelRect[0] + panels.panelRect[2] - data->DisplayPos.x) * sx));
  const int top = static_cast<int>(std::floor((panels.panelRect[1] - data->DisplayPos.y) * sy));
  const int bottom = static_cast<int>(std::ceil((panels.panelRect[1] + panels.panelRect[3] - data->DisplayPos.y) * sy));
  layer.copyTo(x0, pixelsHigh - bottom, x1 - x0, bottom - top);
  drawLists(panel + 1, data->CmdListsCount);
}

// The touch device replayed scripts speak through.
constexpr SDL_TouchID kReplayTouch = 4242;

// The window's size in points, its drawable size in pixels (different on high-DPI screens).
struct WindowSize {
  int width = 0, height = 0;
  int pixelsWide = 0, pixelsHigh = 0;
  bool minimised = false;
  double aspect() const { return height > 0 ? static_cast<double>(width) / height : 1.0; }
  bool drawable() const { return !minimised && pixelsWide > 0 && pixelsHigh > 0; }
};

WindowSize sizeOf(SDL_Window* window) {
  WindowSize size;
  SDL_GetWindowSize(window, &size.width, &size.height);
  SDL_GL_GetDrawableSize(window, &size.pixelsWide, &size.pixelsHigh);
  size.minimised = (SDL_GetWindowFlags(window) & SDL_WINDOW_MINIMIZED) != 0;
  return size;
}

// Dear ImGui's frame without its SDL backend's ImGui_ImplSDL2_NewFrame: that one calls
// SDL_CaptureMouse every frame, which on X11 swallows touch events (SDL #11469, imgui #8150). The
// backend still handles keys, text and the wheel (ImGui_ImplSDL2_ProcessEvent); position and
// buttons come from here.
struct ImGuiMouse {
  bool pressed[3] = {false, false, false};  // a press this frame, so a click shorter than a frame counts

  void newFrame(SDL_Window* window, const WindowSize& size, double seconds) {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(size.width), static_cast<float>(size.height));
    if (size.width > 0 && size.height > 0) {
      io.DisplayFramebufferScale = ImVec2(static_cast<float>(size.pixelsWide) / static_cast<float>(size.width),
                                          static_cast<float>(size.pixelsHigh) / static_cast<float>(size.height));
    }
    io.DeltaTime = static_cast<float>(std::max(seconds, 1e-4));
    int x = 0, y = 0;
    const Uint32 buttons = SDL_GetMouseState(&x, &y);
    io.MousePos = SDL_GetMouseFocus() == window ? ImVec2(static_cast<float>(x), static_cast<float>(y))
                                                : ImVec2(-FLT_MAX, -FLT_MAX);
    const Uint32 masks[3] = {SDL_BUTTON(SDL_BUTTON_LEFT), SDL_BUTTON(SDL_BUTTON_RIGHT), SDL_BUTTON(SDL_BUTTON_MIDDLE)};
    for (int i = 0; i < 3; ++i) {
      io.MouseDown[i] = pressed[i] || (buttons & masks[i]) != 0;
      pressed[i] = false;
    }
  }
  void press(int sdlButton) {
    if (sdlButton == SDL_BUTTON_LEFT) pressed[0] = true;
    if (sdlButton == SDL_BUTTON_RIGHT) pressed[1] = true;
    if (sdlButton == SDL_BUTTON_MIDDLE) pressed[2] = true;
  }
};

// An event to Dear ImGui's SDL backend. A key's modifiers are the event's own: the backend (1.86)
// reads SDL_GetModState(), the state after every event SDL has taken in, so a Ctrl+A pressed and let
// go within one frame reached it as a plain A (a panel's field then kept its text and took what
// was typed where it was clicked).
void toImGui(SDL_Event& event) {
  ImGui_ImplSDL2_ProcessEvent(&event);
  if (event.type != SDL_KEYDOWN && event.type != SDL_KEYUP) return;
  ImGuiIO& io = ImGui::GetIO();
  const Uint16 mod = event.key.keysym.mod;
  io.KeyShift = (mod & KMOD_SHIFT) != 0;
  io.KeyCtrl = (mod & KMOD_CTRL) != 0;
  io.KeyAlt = (mod & KMOD_ALT) != 0;
  io.KeySuper = (mod & KMOD_GUI) != 0;
}

// A key Dear ImGui does something with when it sees it held (not a character it takes as text):
// editing and moving keys, and any key with Ctrl, Alt or the system key down.
bool actsInImGui(const SDL_Keysym& key) {
  switch (key.scancode) {
    case SDL_SCANCODE_LCTRL:
    case SDL_SCANCODE_RCTRL:
    case SDL_SCANCODE_LSHIFT:
    case SDL_SCANCODE_RSHIFT:
    case SDL_SCANCODE_LALT:
    case SDL_SCANCODE_RALT:
    case SDL_SCANCODE_LGUI:
    case SDL_SCANCODE_RGUI: return false;  // a modifier alone
    case SDL_SCANCODE_RETURN:
    case SDL_SCANCODE_KP_ENTER:
    case SDL_SCANCODE_ESCAPE:
    case SDL_SCANCODE_BACKSPACE:
    case SDL_SCANCODE_DELETE:
    case SDL_SCANCODE_TAB:
    case SDL_SCANCODE_LEFT:
    case SDL_SCANCODE_RIGHT:
    case SDL_SCANCODE_UP:
    case SDL_SCANCODE_DOWN:
    case SDL_SCANCODE_HOME:
    case SDL_SCANCODE_END:
    case SDL_SCANCODE_PAGEUP:
    case SDL_SCANCODE_PAGEDOWN:
    case SDL_SCANCODE_INSERT: return true;
    default: return (key.mod & (KMOD_CTRL | KMOD_ALT | KMOD_GUI)) != 0;
  }
}

void pushTouch(SDL_Window* window, Uint32 type, int finger, glm::dvec2 at) {
  SDL_Event event{};
  event.type = type;
  event.tfinger.timestamp = SDL_GetTicks();
  event.tfinger.touchId = kReplayTouch;
  event.tfinger.fingerId = finger;
  event.tfinger.x = static_cast<float>(at.x);
  event.tfinger.y = static_cast<float>(at.y);
  event.tfinger.pressure = 1.0f;
  event.tfinger.windowID = SDL_GetWindowID(window);
  SDL_PushEvent(&event);
}

// Replays a gesture script through SDL: downs, moves and ups become touch events pushed onto SDL's
// queue, so they travel the same path as a real touch screen's; the rest (pin, lift, unpin, mode,
// plane) have no touch event and are applied to the interaction directly.
class TouchReplay {
 public:
  // The script's times count from `startStep`, the world's step as it begins (a snapshot's).
  TouchReplay(interact::GestureScript script, std::int64_t startStep)
      : script_(std::move(script)), clock_(script_), startStep_(startStep) {}

  const interact::GestureScript& script() const { return script_; }

  void beforeStep(SDL_Window* window, Session& session, double aspect) {
    const double dt = session.world().settings().solver.dt;
    // (A reset or a load mid-replay moves the clock: back, and the script waits for it; on, to a
    // snapshot's, and what was due by then comes at once.)
    const std::int64_t steps = std::max<std::int64_t>(0, session.world().stepCount() - startStep_);
    for (const interact::ReplayAction& action : clock_.advance(static_cast<double>(steps) * dt, dt)) {
      const interact::GestureEvent& e = script_.events[action.index];
      const std::optional<glm::dvec2> at = action.pointer.kind == interact::Pointer::Kind::screen
                                               ? std::optional<glm::dvec2>(action.pointer.screen)
                                               : session.camera().project(action.pointer.world, aspect);
      using T = interact::GestureEvent::Type;
      const T type = action.onTheWay ? T::move : e.type;
      // A world point (and a down's radius) travels beside its touch event, so the finger goes
      // exactly where drape-cli replay puts it; such a point is replayed even where the camera
      // cannot see it. A screen point is seen through the script's camera (the interaction's aspect
      // is the script's while it plays).
      const bool world = action.pointer.kind == interact::Pointer::Kind::world;
      const Beside beside{world ? std::optional(action.pointer.world) : std::nullopt,
                          type == T::down ? e.radius : std::nullopt};
      switch (type) {
        case T::down:
        case T::move:
          if (at || world) {
            pushTouch(window, type == T::down ? SDL_FINGERDOWN : SDL_FINGERMOTION, e.finger,
                      at.value_or(glm::dvec2{0.5}));
            beside_[e.finger].push_back(beside);
          }
          break;
        case T::up:
          pushTouch(window, SDL_FINGERUP, e.finger, at.value_or(glm::dvec2{0.5}));
          beside_[e.finger].push_back({});
          break;
        default: break;
      }
      // Everything in order: what has no touch event waits until the touches before it are handled.
      pending_.push_back(action);
    }
  }

  // What the script said of the oldest replayed touch event of `finger` still in SDL's queue, that
  // a touch event cannot carry: its world point and its radius (events of one finger come out of
  // the queue in the order they went in).
  void completeTouch(std::int64_t finger, InputEvent& event) {
    std::deque<Beside>& queue = beside_[finger];
    if (queue.empty()) return;
    event.world = queue.front().world;
    event.radius = queue.front().radius;
    queue.pop_front();
  }

  // After SDL's queue (and with it the touches pushed above) has been handled.
  void afterEvents(Session& session, const InputMapper& input) {
    using T = interact::GestureEvent::Type;
    for (const interact::ReplayAction& action : pending_) {
      const interact::GestureEvent& e = script_.events[action.index];
      if (action.onTheWay) continue;
      const std::optional<int> id = input.touchFinger(kReplayTouch, e.finger);
      switch (e.type) {
        case T::pin:
          if (id) session.interaction().pin(*id);
          break;
        case T::lift:
          if (id) session.interaction().lift(*id, e.height);
          break;
        case T::unpin:
          session.interaction().unpin(action.pointer, e.radius.value_or(session.interaction().settings().radius));
          break;
        case T::mode: session.interaction().setMode(e.mode); break;
        case T::plane: session.interaction().setPlane(e.plane); break;
        default: break;
      }
    }
    pending_.clear();
  }

 private:
  interact::GestureScript script_;
  interact::ReplayClock clock_;
  std::int64_t startStep_;
  std::vector<interact::ReplayAction> pending_;
  struct Beside {
    std::optional<interact::Vec3> world;
    std::optional<double> radius;
  };
  std::map<std::int64_t, std::deque<Beside>> beside_;
};

InputEvent mouseEvent(InputEvent::Kind kind, int x, int y, const WindowSize& size) {
  InputEvent event;
  event.kind = kind;
  event.x = size.width > 0 ? static_cast<double>(x) / size.width : 0.0;
  event.y = size.height > 0 ? static_cast<double>(y) / size.height : 0.0;
  const SDL_Keymod mods = SDL_GetModState();
  event.shift = (mods & KMOD_SHIFT) != 0;
  event.ctrl = (mods & KMOD_CTRL) != 0;
  return event;
}

std::optional<InputEvent> translate(const SDL_Event& e, const WindowSize& size) {
  InputEvent event;
  switch (e.type) {
    case SDL_FINGERDOWN:
    case SDL_FINGERMOTION:
    case SDL_FINGERUP:
      event.kind = e.type == SDL_FINGERDOWN ? InputEvent::Kind::touchDown
                   : e.type == SDL_FINGERUP ? InputEvent::Kind::touchUp
                                            : InputEvent::Kind::touchMove;
      event.touch = e.tfinger.touchId;
      event.finger = e.tfinger.fingerId;
      event.x = e.tfinger.x;
      event.y = e.tfinger.y;
      return event;
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:
      if (e.button.which == SDL_TOUCH_MOUSEID) return std::nullopt;  // a touch's echo
      event = mouseEvent(e.type == SDL_MOUSEBUTTONDOWN ? InputEvent::Kind::mouseDown : InputEvent::Kind::mouseUp,
                         e.button.x, e.button.y, size);
      event.button = e.button.button == SDL_BUTTON_LEFT ? 1 : e.button.button == SDL_BUTTON_MIDDLE ? 2 : 3;
      return event;
    case SDL_MOUSEMOTION:
      if (e.motion.which == SDL_TOUCH_MOUSEID) return std::nullopt;
      return mouseEvent(InputEvent::Kind::mouseMove, e.motion.x, e.motion.y, size);
    case SDL_MOUSEWHEEL:
      if (e.wheel.which == SDL_TOUCH_MOUSEID) return std::nullopt;
      event.kind = InputEvent::Kind::wheel;
      event.wheel = e.wheel.y * (e.wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -1.0 : 1.0);
      return event;
    case SDL_WINDOWEVENT:
      if (e.window.event != SDL_WINDOWEVENT_FOCUS_LOST) return std::nullopt;
      event.kind = InputEvent::Kind::focusLost;
      return event;
    default: return std::nullopt;
  }
}

KeyAction keyAction(SDL_Keycode key, bool ctrl) {
  switch (key) {
    case SDLK_SPACE: return KeyAction::pause;
    case SDLK_n:
    case SDLK_PERIOD: return KeyAction::step;
    case SDLK_r: return KeyAction::reset;
    case SDLK_u: return KeyAction::undo;
    case SDLK_z:
      return ctrl ? ((SDL_GetModState() & KMOD_SHIFT) != 0 ? KeyAction::redo : KeyAction::undo) : KeyAction::none;
    case SDLK_y: return ctrl ? KeyAction::redo : KeyAction::none;
    case SDLK_p:
    case SDLK_F12: return KeyAction::screenshot;
    case SDLK_1: return KeyAction::sticky;
    case SDLK_2: return KeyAction::cut;
    case SDLK_3: return KeyAction::create;
    case SDLK_v: return KeyAction::plane;
    case SDLK_h:
    case SDLK_F1: return KeyAction::help;
    case SDLK_TAB: return KeyAction::panels;
    case SDLK_s: return ctrl ? KeyAction::save : KeyAction::none;
    case SDLK_o: return ctrl ? KeyAction::load : KeyAction::none;
    case SDLK_q: return ctrl ? KeyAction::quit : KeyAction::none;
    case SDLK_ESCAPE: return KeyAction::askQuit;
    case SDLK_f: return KeyAction::frame;
    case SDLK_HOME: return KeyAction::resetView;
    case SDLK_w: return KeyAction::edges;
    case SDLK_c: return KeyAction::strain;
    default: return KeyAction::none;
  }
}

std::string screenshotName() {
  for (int n = 1; n < 100000; ++n) {
    char name[64];
    std::snprintf(name, sizeof name, "drape-screenshot-%03d.png", n);
    if (!std::filesystem::exists(name)) return name;
  }
  return "drape-screenshot.png";
}

// Reads back the window (scene and panels) and writes it as PNG. Returns a message for the HUD.
std::string screenshot(const render::Renderer& renderer, const WindowSize& size, const std::string& file) {
  try {
    scene::writeFileAtomically(
        file, cli::encodePng(renderer.readPixels(size.pixelsWide, size.pixelsHigh), size.pixelsWide, size.pixelsHigh));
    return "screenshot: " + file;
  } catch (const scene::InputError& error) {
    return error.what();
  }
}

}  // namespace

int runApp(const AppOptions& options) {
  // Touches must not also arrive as mouse events, nor the mouse as touches.
  SDL_SetHint(SDL_HINT_TOUCH_MOUSE_EVENTS, "0");
  SDL_SetHint(SDL_HINT_MOUSE_TOUCH_EVENTS, "0");

  std::unique_ptr<Session> session;
  std::optional<interact::GestureScript> script;
  try {
    session = std::make_unique<Session>(options.scene);
    // Every core steps the world (up to 8; the picture is the same bit for bit with one).
    session->setThreads(options.threads ? *options.threads
                                        : static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u)));
    if (options.replay) script = scene::loadGesture(*options.replay);
  } catch (const scene::InputError& error) {
    std::cerr << "drape: error: " << error.what() << "\n";
    return 2;
  }

  const auto set = [](const char* name) { return std::getenv(name) && *std::getenv(name); };
  if (!set("DISPLAY") && !set("WAYLAND_DISPLAY") && !set("SDL_VIDEODRIVER")) {
    // Asking SDL would probe every driver (and libraries print their complaints): say it once.
    std::cerr
        << "drape: no display: set DISPLAY (X11) or WAYLAND_DISPLAY (drape-cli render draws scenes without one)\n";
    return kExitNoDisplay;
  }
  if (SDL_Init(SDL_INIT_VIDEO | SDL_INIT_TIMER) != 0) {
    std::cerr << "drape: no display: " << SDL_GetError() << " (drape-cli render draws scenes without one)\n";
    return kExitNoDisplay;
  }
  // With no display SDL falls back to drivers that draw nowhere: that is no display, unless asked for.
  const std::string driver = SDL_GetCurrentVideoDriver() ? SDL_GetCurrentVideoDriver() : "";
  if ((driver == "offscreen" || driver == "dummy") && !std::getenv("SDL_VIDEODRIVER")) {
    std::cerr
        << "drape: no display: set DISPLAY (X11) or WAYLAND_DISPLAY (drape-cli render draws scenes without one)\n";
    SDL_Quit();
    return kExitNoDisplay;
  }
  SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
  SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
  SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
  SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
  SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 24);
  SDL_Window* window =
      SDL_CreateWindow("Drape", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, options.width, options.height,
                       SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI);
  SDL_GLContext context = window ? SDL_GL_CreateContext(window) : nullptr;
  if (!context) {
    std::cerr << "drape: no display: cannot open a window with OpenGL 3.3 core: " << SDL_GetError()
              << " (drape-cli render draws scenes without one)\n";
    if (window) SDL_DestroyWindow(window);
    SDL_Quit();
    return kExitNoDisplay;
  }
  SDL_GL_MakeCurrent(window, context);
  // A replay runs one step per frame, as fast as it can: frames, not seconds, are its clock.
  SDL_GL_SetSwapInterval(script ? 0 : 1);

  int exitCode = 0;
  {
    std::unique_ptr<render::Renderer> renderer;
    try {
      renderer = std::make_unique<render::Renderer>(reinterpret_cast<render::GetProcAddress>(SDL_GL_GetProcAddress));
    } catch (const render::RenderError& error) {
      std::cerr << "drape: no display: " << error.what() << "\n";
      SDL_GL_DeleteContext(context);
      SDL_DestroyWindow(window);
      SDL_Quit();
      return kExitNoDisplay;
    }
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini written into the working folder
    ImGui::StyleColorsDark();
    ImGui_ImplSDL2_InitForOpenGL(window, context);
    ImGui_ImplOpenGL3_Init("#version 330 core");

    ImGuiMouse imguiMouse;
    std::vector<SDL_Event> heldKeys;  // for ImGui in the next frame (below)
    PanelState panels;
    render::Layer panelLayer;  // the main panel's picture (drawImGui)
    if (options.renderScale) {
      panels.renderScale.setAutomatic(false);
      panels.renderScale.set(*options.renderScale);
    }
    FrameStats stats;
    FixedStepper stepper;
    interact::GestureScript recording;
    recording.camera = session->camera();
    std::optional<TouchReplay> replay;
    if (script) {
      replay.emplace(std::move(*script), session->world().stepCount());
      const interact::GestureScript& s = replay->script();
      session->interaction().settings() = s.settings;
      session->interaction().settings().material = scene::drawnClothTemplate(session->scene());
      if (s.camera) {
        session->camera() = *s.camera;
      } else {
        // Framed to hold where the fingers go too: the tear pulls its pieces 40 cm apart and more,
        // one of them behind the panel from the scene's own view.
        session->alsoFrame(Session::worldPoints(s));
      }
    }
    std::unique_ptr<InputMapper> input;
    interact::Interaction* mapped = nullptr;
    const auto remap = [&] {
      // A new session (load, reset) has a new interaction: the input layer and the recorder follow it.
      if (mapped == &session->interaction()) return;
      mapped = &session->interaction();
      input = std::make_unique<InputMapper>(session->interaction(), session->camera());
      if (options.record) {
        Session* s = session.get();
        // Times from the step the session began at (a snapshot's), as a replay counts them.
        const std::int64_t from = session->world().stepCount();
        session->interaction().record = [s, from, &recording](const interact::GestureEvent& e) {
          interact::GestureEvent timed = e;
          timed.time = static_cast<double>(s->world().stepCount() - from) * s->world().settings().solver.dt;
          if (recording.events.empty() || recording.events.back().time <= timed.time) recording.events.push_back(timed);
        };
      }
    };
    remap();

    std::int64_t frame = 0;
    TimingLog timings;
    WindowSize timedSize = sizeOf(window);
    bool running = true;
    std::optional<Clock::time_point> quitAsked;
    // The first view is framed once the panel's width is known, unless a script brought its camera.
    bool framed = replay && replay->script().camera.has_value();
    Clock::time_point last = Clock::now();
    while (running) {
      const Clock::time_point now = Clock::now();
      const double elapsed = std::chrono::duration<double>(now - last).count();
      last = now;
      WindowSize size = sizeOf(window);
      // Screen points of a script with a camera are points of its picture, at its aspect.
      session->interaction().setCamera(session->camera(),
                                       replay && replay->script().camera ? replay->script().aspect : size.aspect());
      if (replay) replay->beforeStep(window, *session, size.aspect());

      bool stepOnce = false;
      const InputMapper* mapperBefore = input.get();
      const std::int64_t fingerMovesBefore = input->fingerMoves();
      // Dear ImGui (1.86) reads a key as held or not when its frame begins: a key pressed and let go
      // between two frames never reached it. A tap within one frame (xdotool's, or a quick one while
      // a frame takes long) left a panel's field open after its Return, and the next key and click
      // went to the field. So once a key ImGui acts on (Return, Backspace, an arrow, a Ctrl chord...)
      // was pressed in this frame, the next release, and every key and character after it, reach
      // ImGui in the next frame, in order (a Ctrl let go in the frame of its A would otherwise leave
      // a plain A). Characters typed alone all go at once: ImGui takes them as text.
      // (A key pressed again in the frame it was let go in waits as well: ImGui would see it held
      // through both frames, and take two Backspaces as one.)
      bool acted = false, holding = false;
      std::vector<SDL_Scancode> released;
      const auto keyToImGui = [&](SDL_Event& e) {
        if (!holding && e.type == SDL_KEYUP && acted) holding = true;
        if (!holding && e.type == SDL_KEYDOWN &&
            std::find(released.begin(), released.end(), e.key.keysym.scancode) != released.end()) {
          holding = true;
        }
        if (holding) {
          heldKeys.push_back(e);
          return;
        }
        if (e.type == SDL_KEYDOWN) acted = acted || actsInImGui(e.key.keysym);
        if (e.type == SDL_KEYUP) released.push_back(e.key.keysym.scancode);
        toImGui(e);
      };
      std::vector<SDL_Event> fromLastFrame;
      fromLastFrame.swap(heldKeys);
      for (SDL_Event& held : fromLastFrame) keyToImGui(held);
      SDL_Event event;
      while (SDL_PollEvent(&event)) {
        const bool touch = event.type == SDL_FINGERDOWN || event.type == SDL_FINGERMOTION || event.type == SDL_FINGERUP;
        const bool key = event.type == SDL_KEYDOWN || event.type == SDL_KEYUP || event.type == SDL_TEXTINPUT;
        if (key) {
          keyToImGui(event);
        } else if (!touch) {
          toImGui(event);
        }
        if (event.type == SDL_QUIT) running = false;
        if (event.type == SDL_MOUSEBUTTONDOWN && event.button.which != SDL_TOUCH_MOUSEID) {
          imguiMouse.press(event.button.button);
        }
        if (event.type == SDL_KEYDOWN && !ImGui::GetIO().WantCaptureKeyboard) {
          const KeyAction action = keyAction(event.key.keysym.sym, (event.key.keysym.mod & KMOD_CTRL) != 0);
          if (action == KeyAction::quit) running = false;
          if (action == KeyAction::askQuit && event.key.repeat != 0) {
            // Esc held down repeats: that is one press, not the second that quits.
          } else if (action == KeyAction::askQuit && ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopup)) {
            panels.closePopups = true;  // Esc closes an open list first, and does not count towards quitting
          } else if (action == KeyAction::askQuit) {
            // Esc twice within 3 s: one stray press does not throw away drawn cloths and cuts.
            const Clock::time_point pressed = Clock::now();
            if (quitAsked && pressed - *quitAsked < std::chrono::seconds(3)) {
              running = false;
            } else {
              quitAsked = pressed;
              session->status = "press Esc again to quit (Ctrl+S saves first)";
            }
          }
          if (action == KeyAction::step) stepOnce = true;
          if (action == KeyAction::screenshot && size.drawable()) panels.wantScreenshot = true;
          applyKey(action, *session, panels);
          remap();
        }
        size = sizeOf(window);
        if (std::optional<InputEvent> input_event = translate(event, size)) {
          if (replay && touch && event.tfinger.touchId == kReplayTouch) {
            replay->completeTouch(event.tfinger.fingerId, *input_event);
          }
          // Over a panel as the panels were last drawn, for this event where it is now (the wheel's
          // own event has no position: the pointer's is taken); touches always reach the cloth.
          double x = input_event->x, y = input_event->y;
          if (input_event->kind == InputEvent::Kind::wheel) {
            int px = 0, py = 0;
            SDL_GetMouseState(&px, &py);
            x = size.width > 0 ? static_cast<double>(px) / size.width : 0.0;
            y = size.height > 0 ? static_cast<double>(py) / size.height : 0.0;
          }
          const bool overUi = !touch && (overAny(panels.windows, x, y) || ImGui::IsAnyItemActive());
          input->handle(*input_event, overUi);
        }
      }
      session->keepCameraAboveTable();
      session->ageSeams(replay ? session->world().settings().solver.dt : elapsed);

      if (replay) replay->afterEvents(*session, *input);

      // Simulate: whole steps at the scene's dt, paced by the wall clock (one per frame in a replay).
      const double dt = session->world().settings().solver.dt;
      // While paused, a step each frame a finger moved: a drag is not lost, the cloth follows the
      // hand and stops when it stops.
      const bool handMoved = input.get() == mapperBefore && input->fingerMoves() != fingerMovesBefore;
      int steps = replay ? 1 : session->paused ? (stepOnce || handMoved ? 1 : 0) : stepper.advance(elapsed, dt);
      if (session->paused) stepper.reset();
      const Clock::time_point simStart = Clock::now();
      for (int i = 0; i < steps; ++i) {
        if (session->step() == sim::StepStatus::diverged) {
          if (options.exitAfter) exitCode = 1;
          break;
        }
      }
      stats.simulation(std::chrono::duration<double>(Clock::now() - simStart).count(), steps, stepper.fellBehind());

      // Draw: the scene, then the panels over it. A minimised or zero-size window draws nothing.
      const Clock::time_point drawStart = Clock::now();
      double frameScale = 1.0;  // the render scale this frame was drawn at
      if (size.drawable()) {
        render::FrameOptions frameOptions = panels.frameOptions;
        frameOptions.renderScale = static_cast<float>(panels.renderScale.scale());
        frameScale = panels.renderScale.scale();
        frameOptions.hiddenRight = size.width > 0
                                       ? static_cast<int>(panels.hiddenRight * static_cast<float>(size.pixelsWide) /
                                                          static_cast<float>(size.width))
                                       : 0;
        renderer->render(session->world(), session->camera(), size.pixelsWide, size.pixelsHigh, frameOptions,
                         fingerOverlay(*session, *input));
        renderer->finish();
        const Clock::time_point panelStart = Clock::now();
        // Shown from the next frame, with the other parts of this one (the HUD is drawn below).
        const double sceneSeconds = std::chrono::duration<double>(panelStart - drawStart).count();
        ImGui_ImplOpenGL3_NewFrame();
        imguiMouse.newFrame(window, size, elapsed);
        ImGui::NewFrame();
        const std::optional<std::filesystem::path> toLoad = drawPanels(*session, panels, stats, *input);
        stats.sceneSeconds = sceneSeconds;
        ImGui::Render();
        drawImGui(ImGui::GetDrawData(), panels, panelLayer, size.pixelsWide, size.pixelsHigh);
        session->setView(size.aspect(), size.width > 0 ? panels.panelWidth / static_cast<float>(size.width) : 0.0);
        if (!framed && panels.panelWidth > 0.0f) {
          session->resetView();  // now that the panel's width is known: the scene beside it
          framed = true;
        }
        if (toLoad) session->load(*toLoad);  // on failure the message is in the status line and the scene stays
        remap();                             // a load, reset or model change made a new interaction
        for (const auto& [after, file] : options.screenshots) {
          if (frame + 1 != after) continue;
          const std::string said = screenshot(*renderer, size, file);
          if (said.rfind("screenshot: ", 0) != 0) {
            std::cerr << "drape: error: " << said << "\n";
            exitCode = 2;
          }
        }
        if (panels.wantScreenshot) {
          session->status = screenshot(*renderer, size, screenshotName());
          panels.wantScreenshot = false;
        }
        renderer->finish();
        const Clock::time_point swapStart = Clock::now();
        stats.panelSeconds = std::chrono::duration<double>(swapStart - panelStart).count();
        SDL_GL_SwapWindow(window);
        stats.swapSeconds = std::chrono::duration<double>(Clock::now() - swapStart).count();
      } else {
        SDL_Delay(16);  // nothing to draw: do not spin
      }
      stats.drawing(std::chrono::duration<double>(Clock::now() - drawStart).count(), elapsed);
      if (size.drawable()) {
        panels.renderScale.frame(stats.simulationSeconds + stats.sceneSeconds + stats.panelSeconds, stats.sceneSeconds);
      }
      if (options.timings && size.drawable()) {
        timings.add(elapsed, stats, frameScale);
        timedSize = size;
      }

      ++frame;
      if (options.exitAfter && frame >= *options.exitAfter) running = false;
    }

    if (options.out) {
      // A snapshot (NAME.drape.json) as the panel's save writes it, else the state as drape-cli's.
      std::optional<std::string> failed;
      if (scene::isSnapshotName(*options.out)) {
        failed = session->save(*options.out);
      } else {
        try {
          scene::writeFileAtomically(*options.out,
                                     scene::stateDocument(session->scene(), session->world())
                                             .dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
                                         "\n");
        } catch (const scene::InputError& error) {
          failed = error.what();
        }
      }
      if (failed) {
        std::cerr << "drape: error: " << *failed << "\n";
        exitCode = 2;
      }
    }
    if (options.record) {
      recording.settings = session->interaction().settings();  // radius, pinch, lift, spacing as they were
      try {
        scene::writeFileAtomically(*options.record, scene::gestureDocument(recording).dump(1) + "\n");
      } catch (const scene::InputError& error) {
        std::cerr << "drape: error: " << error.what() << "\n";
        exitCode = 2;
      }
    }
    if (options.timings) std::cout << timings.summary(timedSize.pixelsWide, timedSize.pixelsHigh) << std::endl;
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplSDL2_Shutdown();
    ImGui::DestroyContext();
  }
  SDL_GL_DeleteContext(context);
  SDL_DestroyWindow(window);
  SDL_Quit();
  return exitCode;
}

}  // namespace drape::app
