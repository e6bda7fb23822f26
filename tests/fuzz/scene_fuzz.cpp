// Fuzzes the scene reader as drape-cli uses it: scene text, then `--set` overrides, then the engine.
//
// The input is the scene's JSON up to the first NUL byte; after it, '\n'-separated `path=value`
// overrides (empty lines skipped). Each is applied as `--set` applies it, the scene is validated,
// and a world made of it is stepped twice (within fuzz_support.hpp's budget). A scene of more than
// 20,000 particles is not built, and one whose drawn cloths could have more is not even read
// (reading builds the outline): large, so slow by design, not hostile. A scene that names a mesh
// reads it relative to the working directory (the scene's source is "fuzz.json"): tools/fuzz and
// the replay test run in assets/scenes, where "../meshes/dome.obj" resolves.
//
// Expected failures: InputError (the scene layer's word on a bad file) and std::invalid_argument
// (the engine's own validation). Anything else escapes, and libFuzzer reports it.
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/input.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/world.hpp"
#include "fuzz_support.hpp"

using namespace drape;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input = fuzz::text(data, size);
  const std::size_t nul = input.find('\0');
  const std::string_view sceneText = input.substr(0, nul);
  std::string_view overrides = nul == std::string_view::npos ? std::string_view{} : input.substr(nul + 1);
  try {
    nlohmann::json document = scene::parseJson(sceneText, "fuzz.json");
    while (!overrides.empty()) {
      const std::size_t end = overrides.find('\n');
      const std::string_view line = overrides.substr(0, end);
      overrides = end == std::string_view::npos ? std::string_view{} : overrides.substr(end + 1);
      if (!line.empty()) scene::applyOverride(document, line);
    }
    if (fuzz::estimatedOutlineParticles(document) > fuzz::kMaxWorldParticles) return 0;
    const scene::Scene scene = scene::parseScene(document, "fuzz.json");
    const double particles = fuzz::estimatedParticles(scene.world);
    if (particles > fuzz::kMaxWorldParticles) return 0;
    sim::World world(scene.world);
    const int steps = fuzz::affordableSteps(scene.world, particles, 2);
    for (int i = 0; i < steps; ++i) world.step();
  } catch (const scene::InputError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
