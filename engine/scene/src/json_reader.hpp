// A strict reader over one JSON object: every key read is checked for type, finiteness and range,
// every key not read is an error, and every error names the source and the dotted key path.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <set>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/input.hpp"
#include "drape/sim/types.hpp"

namespace drape::scene {

// Limits and units shared by the scene and gesture readers.
inline constexpr double kMaxCoordinate = 1.0e4;                     // m
inline constexpr double kDegrees = 3.14159265358979323846 / 180.0;  // radians a degree

struct Range {
  double min;
  double max;
  bool minExclusive = false;
  std::string_view unit = "";
};

class ObjectReader {
 public:
  // `path` is the dotted path of `node` ("" for the document itself).
  ObjectReader(const nlohmann::json& node, std::string path, const std::string& source);

  bool has(std::string_view key) const;
  double number(std::string_view key, double fallback, const Range& range);
  int integer(std::string_view key, int fallback, int min, int max);
  std::string text(std::string_view key, std::string fallback);
  bool boolean(std::string_view key, bool fallback);
  std::string choice(std::string_view key, std::string fallback, std::initializer_list<std::string_view> choices);
  sim::Vec3 vec3(std::string_view key, sim::Vec3 fallback, double maxAbs, std::string_view unit);
  ObjectReader object(std::string_view key);
  // The value at `key` unchecked (nullptr if absent), for shapes the caller checks itself.
  const nlohmann::json* raw(std::string_view key) { return find(key); }
  // The array at `key` (empty if absent), checked to hold at most maxSize elements.
  const nlohmann::json& array(std::string_view key, std::size_t maxSize);
  // Fails on the first key that was never read.
  void finish() const;

  std::string pathOf(std::string_view key) const;
  const std::string& source() const { return source_; }
  [[noreturn]] void fail(std::string_view key, std::string_view expected, const nlohmann::json* got) const;

 private:
  const nlohmann::json& node_;
  std::string path_;
  const std::string& source_;
  std::set<std::string, std::less<>> read_;
  const nlohmann::json* find(std::string_view key);
};

// "path: expected X, got Y" for a value outside an object reader (array elements).
[[noreturn]] void failAt(const std::string& source, const std::string& path, std::string_view expected,
                         const nlohmann::json* got);
std::string describe(const nlohmann::json& value);
std::string formatRange(const Range& range);
// Reads a JSON file of at most maxBytes strictly (drape/scene/input.hpp); `what` names it in
// messages ("scene file"). Throws InputError.
nlohmann::json readJsonFile(const std::filesystem::path& file, std::string_view what, std::size_t maxBytes);

// Reads [x, y, z] at `path`.
sim::Vec3 readVec3(const nlohmann::json& value, const std::string& path, const std::string& source, double maxAbs,
                   std::string_view unit);

}  // namespace drape::scene
