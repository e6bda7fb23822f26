// Gesture script files: JSON <-> interact::GestureScript, read as strictly as scene files.
// Every key is documented in docs/gestures.md. Malformed files are InputErrors naming the file and
// the key; events that are well formed but cannot be honoured when replayed (a finger that is not
// down) are the replay's business: reported and skipped.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "drape/interact/replay.hpp"
#include "drape/scene/scene.hpp"

namespace drape::scene {

interact::GestureScript loadGesture(const std::filesystem::path& file);
interact::GestureScript parseGesture(const nlohmann::json& document, const std::string& source);
// Writes a script back as JSON (what the app records).
nlohmann::json gestureDocument(const interact::GestureScript& script);

}  // namespace drape::scene
