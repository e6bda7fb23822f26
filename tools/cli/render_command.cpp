// drape-cli render: the same engine, drawn by the same renderer as the app, in an off-screen
// OSMesa context, written as PNG.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "context.hpp"
#include "drape/render/renderer.hpp"
#include "drape/scene/error.hpp"
#include "drape/scene/output.hpp"
#include "png.hpp"

namespace drape::cli {

namespace {

constexpr double kDegrees = 3.14159265358979323846 / 180.0;

std::vector<double> numbers(const std::string& text) {
  std::vector<double> values;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data() + begin, text.data() + comma, value);
    if (error != std::errc{} || end != text.data() + comma || !std::isfinite(value)) return {};
    values.push_back(value);
    begin = comma + 1;
  }
  return values;
}

void parseSize(const std::string& text, int& width, int& height) {
  const std::size_t x = text.find('x');
  const auto parse = [](std::string_view part, int& value) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    return error == std::errc{} && end == part.data() + part.size() && value >= 16 && value <= 8192;
  };
  if (x == std::string::npos || !parse(std::string_view(text).substr(0, x), width) ||
      !parse(std::string_view(text).substr(x + 1), height)) {
    throw scene::InputError("--size " + text + ": expected WxH with each from 16 to 8192, e.g. 800x600");
  }
}

// Presets look at the whole scene from a fixed direction; numbers place the camera exactly.
render::Camera makeCamera(const std::string& text, const sim::World& world, double aspect) {
  glm::dvec3 lower, upper;
  render::sceneBounds(world, lower, upper);
  struct Preset {
    const char* name;
    double yaw, pitch;  // degrees
  };
  for (const Preset& preset :
       {Preset{"auto", 35.0, 22.0}, Preset{"front", 0.0, 8.0}, Preset{"side", 90.0, 8.0}, Preset{"top", 0.0, 89.0}}) {
    if (text == preset.name)
      return render::Camera::framing(lower, upper, preset.yaw * kDegrees, preset.pitch * kDegrees, aspect);
  }
  const std::vector<double> v = numbers(text);
  if ((v.size() != 3 && v.size() != 6) || !(v[2] > 0.0 && v[2] <= 1000.0) || std::abs(v[1]) > 89.0) {
    throw scene::InputError("--camera " + text +
                            ": expected auto, front, side, top, or yaw,pitch,distance[,x,y,z] (degrees, pitch within "
                            "+-89, distance in (0, 1000] m)");
  }
  render::Camera camera = render::Camera::framing(lower, upper, v[0] * kDegrees, v[1] * kDegrees, aspect);
  camera.distance = v[2];
  if (v.size() == 6) camera.target = glm::dvec3{v[3], v[4], v[5]};
  return camera;
}

// Fingers down at the end of the run: a ring for a sticky finger, the path of a cut or an outline.
render::Overlay fingerOverlay(const Playback& playback) {
  render::Overlay overlay;
  if (!playback.interaction()) return overlay;
  const interact::Interaction& interaction = *playback.interaction();
  for (const interact::TouchView& touch : interaction.touches()) {
    const glm::vec4 colour = touch.mode == interact::Mode::cut      ? glm::vec4{0.9f, 0.1f, 0.1f, 1.0f}
                             : touch.mode == interact::Mode::create ? glm::vec4{0.1f, 0.3f, 0.9f, 1.0f}
                                                                    : glm::vec4{1.0f, 1.0f, 1.0f, 1.0f};
    if (touch.mode == interact::Mode::sticky) {
      overlay.addRing(touch.position, interaction.settings().radius, glm::dvec3{0.0, 1.0, 0.0}, colour);
    } else {
      overlay.addStroke(touch.stroke, colour);
    }
  }
  return overlay;
}

}  // namespace

int render(const RenderArguments& arguments) {
  try {
    const Input input = loadInput(arguments.input);
    const scene::Scene& scene = input.scene;
    Playback playback(input, arguments.gesture);
    sim::World& world = playback.world();
    int width = 0, height = 0;
    parseSize(arguments.size, width, height);
    const double aspect = static_cast<double>(width) / height;
    makeCamera(arguments.camera, world, aspect);  // reject a bad --camera before any work
    if (!arguments.out && !arguments.outDir)
      throw scene::InputError("render: say where the pictures go: --out FILE.png or --every K --out-dir DIR");
    if (arguments.out && std::filesystem::path(*arguments.out).extension() != ".png") {
      throw scene::InputError("--out " + *arguments.out + ": expected a file ending in .png");
    }
    const std::int64_t steps = stepCount(scene, arguments.steps, arguments.seconds, playback.script());

    std::unique_ptr<OffscreenContext> context;
    std::unique_ptr<render::Renderer> renderer;
    try {
      context = OffscreenContext::create(width, height);
      renderer = std::make_unique<render::Renderer>(context->procAddress());
    } catch (const render::RenderError& error) {
      throw scene::InputError(std::string("cannot draw off-screen: ") + error.what());
    }
    render::FrameOptions options;
    options.strainMap = arguments.strain;
    options.wireframe = arguments.edges;
    const auto picture = [&](const render::Camera& camera) {
      renderer->render(world, camera, width, height, options, fingerOverlay(playback));
      return encodePng(renderer->readPixels(width, height), width, height);
    };

    std::vector<std::string> written;
    if (arguments.outDir) {
      // A sequence keeps one camera, framed on the first frame, so the cloth moves and not the view.
      outputFolder(*arguments.outDir);
      const render::Camera camera = makeCamera(arguments.camera, world, aspect);
      // Every frame or none: a run that diverges halfway leaves the folder as it was.
      scene::OutputBatch frames;
      for (std::int64_t step = 0; step <= steps; ++step) {
        if (step > 0 && playback.step() == sim::StepStatus::diverged) return reportDivergence(scene, world);
        if (step % *arguments.every != 0) continue;
        char name[32];
        std::snprintf(name, sizeof name, "frame-%06lld.png", static_cast<long long>(step));
        const std::filesystem::path file = std::filesystem::path(*arguments.outDir) / name;
        frames.add(file, picture(camera));
        written.push_back(file.string());
      }
      frames.commit();
    } else {
      for (std::int64_t step = 0; step < steps; ++step) {
        if (playback.step() == sim::StepStatus::diverged) return reportDivergence(scene, world);
      }
      scene::writeFileAtomically(*arguments.out, picture(makeCamera(arguments.camera, world, aspect)));
      written.push_back(*arguments.out);
    }
    playback.printReports();
    if (!arguments.quiet) {
      std::printf("%s: %s, %dx%d pixels, %s\n", scene.name.c_str(), playback.stepsRun().c_str(), width, height,
                  renderer->description().c_str());
      if (written.size() == 1) {
        std::printf("wrote %s\n", written.front().c_str());
      } else {
        std::printf("wrote %zu frames: %s ... %s\n", written.size(), written.front().c_str(), written.back().c_str());
      }
    }
    return kExitOk;
  } catch (const scene::InputError& error) {
    return badInput(error.what());
  }
}

}  // namespace drape::cli
