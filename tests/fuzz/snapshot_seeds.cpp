// Writes seed snapshots for the snapshot harness (tools/fuzz): small shipped scenes, run a few
// steps, saved as the app saves a session. Usage: fuzz_snapshot_seeds OUT_DIR (run in
// assets/scenes, so that the dome's "../meshes/dome.obj" resolves for the harness as it does here).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/scene/scene.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/world.hpp"

using namespace drape;

namespace {

struct Seed {
  const char* name;
  const char* scene;
  std::vector<std::string> overrides;
  int steps;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_snapshot_seeds OUT_DIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out);
  const std::string six = "cloths.0.grid.columns=6", sixRows = "cloths.0.grid.rows=6";
  const std::vector<Seed> seeds = {
      {"hang", "hang", {six, sixRows, "cloths.0.pins.1.particle=[5,0]"}, 10},
      {"hang-springs", "hang-springs", {six, sixRows, "cloths.0.pins.1.particle=[5,0]"}, 20},
      {"torn", "hang2-tear", {six, sixRows, "cloths.0.pins.1.particle=[5,0]", "tearing.threshold=1.01"}, 40},
      {"torn-lines-tethers",
       "hang2-tear",
       {six, sixRows, "cloths.0.pins.1.particle=[5,0]", "tearing.threshold=1.01", "solver.stretchSolver=\"lines\"",
        "solver.tethers=true"},
       40},
      {"star", "star", {"cloths.0.outline.spacing=0.12"}, 5},
      {"spring", "spring", {}, 5},
      {"fold", "fold", {six, "cloths.0.grid.rows=8", "cloths.0.pins=[{\"particle\":[0,4]},{\"particle\":[5,4]}]"}, 5},
      {"dome", "dome", {six, sixRows}, 5},
      {"desk-ball", "desk-ball", {six, sixRows}, 5},
      {"trampoline",
       "trampoline",
       {six, sixRows, "cloths.0.pins.1.particle=[5,0]", "cloths.0.pins.2.particle=[0,5]",
        "cloths.0.pins.3.particle=[5,5]"},
       5},
  };
  for (const Seed& seed : seeds) {
    const scene::Scene scene = scene::loadScene(scene::resolveScenePath(seed.scene), seed.overrides);
    sim::World world(scene.world);
    world.run(seed.steps);
    std::ofstream(out / (std::string(seed.name) + ".json")) << scene::snapshotDocument(scene, world).dump() << "\n";
  }
  std::printf("fuzz_snapshot_seeds: %zu snapshots in %s\n", seeds.size(), out.c_str());
  return 0;
}
