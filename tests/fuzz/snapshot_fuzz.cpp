// Fuzzes the snapshot reader: the input is a snapshot's JSON text (what the app's save writes).
//
// A snapshot that parses is made into a world (makeWorld), stepped twice (within fuzz_support.hpp's
// budget), then saved again (snapshotDocument) and read back: a saved session must load. Expected
// failures of the first read and of makeWorld: InputError and std::invalid_argument; anything else
// escapes, and libFuzzer reports it.
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/input.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/world.hpp"
#include "fuzz_support.hpp"

using namespace drape;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const nlohmann::json document = scene::parseJson(fuzz::text(data, size), "fuzz.json");
    // Its scene is read as a scene file is: one with a wide drawn cloth is slow by design.
    if (document.is_object() && document.contains("scene") &&
        fuzz::estimatedOutlineParticles(document["scene"]) > fuzz::kMaxWorldParticles) {
      return 0;
    }
    const scene::Snapshot snapshot = scene::parseSnapshot(document, "fuzz.json");
    double particles = 0.0;
    for (const sim::Cloth& cloth : snapshot.cloths) particles += static_cast<double>(cloth.rest.particleCount());
    if (particles > fuzz::kMaxWorldParticles) return 0;
    sim::World world = scene::makeWorld(snapshot);
    const int steps = fuzz::affordableSteps(snapshot.scene.world, particles, 2);
    for (int i = 0; i < steps; ++i) world.step();
    try {
      (void)scene::parseSnapshot(scene::snapshotDocument(snapshot.scene, world), "saved.json");
    } catch (const scene::InputError& error) {
      fuzz::broken("a saved snapshot does not read back:", error.what());
    } catch (const std::invalid_argument& error) {
      fuzz::broken("a saved snapshot does not read back:", error.what());
    }
  } catch (const scene::InputError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
