// Scene files: JSON <-> engine settings, with strict validation.
//
// Every key is documented in docs/scenes.md with its unit and range. Unknown keys, wrong types,
// out-of-range and non-finite values are errors naming the file and the key's dotted path
// (`cloths.0.grid.columns`), the same path `--set` takes. Nothing the user wrote is silently
// replaced; only keys that are absent take their documented defaults.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "drape/sim/settings.hpp"

namespace drape::scene {

struct Scene {
  std::string source;       // file the scene came from (for messages)
  std::string name;         // short name, defaults to the file's stem
  std::string description;  // one line for humans
  double duration = 5.0;    // s, how long a run lasts when the caller does not say
  sim::WorldSettings world;
  std::string document;  // the JSON it was read from, overrides applied (snapshots keep it)
};

// Reads, overrides and validates a scene file. Throws InputError.
Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

// Validates an already parsed document; `source` names it in messages. Throws InputError.
Scene parseScene(const nlohmann::json& document, const std::string& source);

// Applies one `dotted.path=value` assignment to a document. The value is read as JSON when it is
// valid JSON (numbers, true, [1,2,3]) and as a string otherwise (`solver.model=force`). Missing
// object keys on the way are created; array indices must exist. Throws InputError.
void applyOverride(nlohmann::json& document, std::string_view assignment);

// The materials and thickness a cloth drawn into this scene gets: the first cloth's, or the
// model's defaults when the scene has none.
sim::ClothSettings drawnClothTemplate(const Scene& scene);

// The scene with another model or integrator. Materials mean different things in the two models
// (a 0..1 fraction, or N/m), so when the model changes every cloth takes the new model's default
// materials, and XPBD and tethers (position model only) are switched off for the force model. The
// force model also takes as many substeps as its integrator needs to stay stable on the cloths'
// springs (sim::World::stableForceSubstep, with a tenth to spare; at most sim::kMaxSubsteps), if
// that is more than the scene has: a light cloth's springs can need hundreds.
Scene withModel(const Scene& scene, sim::Model model, sim::Integrator integrator);

// The scene with every sheet (lattice or outline; not a chain, which cannot bend as a sheet) made of
// the fabric preset `name` (fabric.hpp), as if its file said "fabric": name: the mass then follows
// from the area, and the materials and per-particle masses go (the document drops them too). A
// scene in the force model moves to the position model first (withModel), where fabrics live.
// Throws std::invalid_argument if there is no such preset.
Scene withFabric(const Scene& scene, std::string_view name);

// Finds a scene by path, or by name in the shipped scenes folder (`hang` -> assets/scenes/hang.json).
std::filesystem::path resolveScenePath(const std::string& nameOrPath);
std::filesystem::path sceneDirectory();

}  // namespace drape::scene
