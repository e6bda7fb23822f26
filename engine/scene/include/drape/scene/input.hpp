// Reading what a user hands us: files and JSON text, within limits checked before anything is
// allocated for them.
//
// Every reader of the scene layer comes through here. A file must be a regular file no larger
// than its kind's limit (a FIFO, a device or a folder is refused at once, never read or waited
// on); JSON is parsed in time and memory linear in its size, with no key twice in one object and
// no deeper nesting than kMaxJsonDepth. docs/scenes.md lists the limits.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "drape/scene/error.hpp"

namespace drape::scene {

inline constexpr int kMaxJsonDepth = 64;  // objects and arrays inside each other

// The largest file of each kind, in bytes. A shipped scene is a few kilobytes; a gesture of the
// largest allowed event count (1,000,000) about 80 MB; a snapshot of the largest allowed world
// (2^20 particles) about 400 MB.
inline constexpr std::size_t kMaxSceneFileBytes = std::size_t{64} << 20;
inline constexpr std::size_t kMaxGestureFileBytes = std::size_t{128} << 20;
inline constexpr std::size_t kMaxSnapshotFileBytes = std::size_t{1} << 30;
inline constexpr std::size_t kMaxMeshFileBytes = std::size_t{256} << 20;

// The whole of `file`, if it is a regular file of at most maxBytes. `what` names it in messages
// ("scene file"). Throws InputError: "FILE: cannot open the WHAT: WHY" (it does not exist, it is a
// folder, it is not a regular file, permission denied, larger than the limit).
std::string readInputFile(const std::filesystem::path& file, std::string_view what, std::size_t maxBytes);

// Parses JSON, refusing a key given twice in one object and nesting deeper than kMaxJsonDepth.
// `source` names the text in messages. Throws InputError.
nlohmann::json parseJson(std::string_view text, const std::string& source);

}  // namespace drape::scene
