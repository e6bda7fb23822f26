// Snapshots: a session saved to a file and loaded back. The scene (its JSON document) and every
// cloth as it is now, torn mesh and all: rest positions, triangles, constraints, positions, previous
// positions, velocities (force model), masses, pins and, where the line solve keeps it (a stretch
// target), the links' tension, so that a loaded world goes on bit for bit. Loading one is as strict as loading a
// scene: anything malformed is an InputError naming the file and the key.
#pragma once

#include <filesystem>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "drape/scene/scene.hpp"
#include "drape/sim/world.hpp"

namespace drape::scene {

struct Snapshot {
  Scene scene;
  double time = 0.0;  // s, when it was taken: a world made from it goes on from there
  std::vector<sim::Cloth> cloths;
};

// Whether a file is a snapshot by its name: NAME.drape.json (what the app's save and drape-cli's
// `--out` write, and what they open as one).
bool isSnapshotName(const std::filesystem::path& file);

nlohmann::json snapshotDocument(const Scene& scene, const sim::World& world);
Snapshot loadSnapshot(const std::filesystem::path& file);
// Validates an already parsed snapshot; `source` names it in messages. Throws InputError.
Snapshot parseSnapshot(const nlohmann::json& document, const std::string& source);

// A world made from the snapshot: the scene's world with its cloths put back. Throws InputError.
sim::World makeWorld(const Snapshot& snapshot);

}  // namespace drape::scene
