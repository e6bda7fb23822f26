// Scene-file colliders and self-collision settings.
#pragma once

#include <nlohmann/json.hpp>

#include "drape/sim/settings.hpp"
#include "json_reader.hpp"

namespace drape::scene {

// Reads `colliders.N`; a mesh collider's OBJ file is found relative to the scene file.
sim::ColliderSettings readCollider(ObjectReader& reader, const std::string& sceneSource);
sim::SelfCollisionSettings readSelfCollision(ObjectReader& reader);

}  // namespace drape::scene
