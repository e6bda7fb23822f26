#include "json_reader.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace drape::scene {

using nlohmann::json;

std::string describe(const nlohmann::json& value) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) return "a non-finite number";
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

std::string formatRange(const Range& range) {
  std::ostringstream out;
  out.precision(12);
  out << "a number " << (range.minExclusive ? "> " : ">= ") << range.min << " and <= " << range.max;
  if (!range.unit.empty()) out << " (" << range.unit << ")";
  return out.str();
}

void failAt(const std::string& source, const std::string& path, std::string_view expected, const nlohmann::json* got) {
  std::string message =
      source + ": " + (path.empty() ? std::string("(document)") : path) + ": expected " + std::string(expected);
  message += got ? ", got " + describe(*got) : ", but it is missing";
  throw InputError(message);
}

ObjectReader::ObjectReader(const nlohmann::json& node, std::string path, const std::string& source)
    : node_(node), path_(std::move(path)), source_(source) {
  if (!node_.is_object()) failAt(source_, path_, "an object { ... }", &node_);
}

std::string ObjectReader::pathOf(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void ObjectReader::fail(std::string_view key, std::string_view expected, const nlohmann::json* got) const {
  failAt(source_, pathOf(key), expected, got);
}

bool ObjectReader::has(std::string_view key) const { return node_.contains(key); }

const nlohmann::json* ObjectReader::find(std::string_view key) {
  const auto it = node_.find(key);
  if (it == node_.end()) return nullptr;
  read_.emplace(key);
  return &*it;
}

double ObjectReader::number(std::string_view key, double fallback, const Range& range) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  const double x = value->is_number() ? value->get<double>() : NAN;
  const bool inRange = std::isfinite(x) && (range.minExclusive ? x > range.min : x >= range.min) && x <= range.max;
  if (!inRange) fail(key, formatRange(range), value);
  return x;
}

int ObjectReader::integer(std::string_view key, int fallback, int min, int max) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  const bool ok = value->is_number_integer() && value->get<long long>() >= min && value->get<long long>() <= max;
  if (!ok) fail(key, "an integer from " + std::to_string(min) + " to " + std::to_string(max), value);
  return value->get<int>();
}

std::string ObjectReader::text(std::string_view key, std::string fallback) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  if (!value->is_string()) fail(key, "a string", value);
  return value->get<std::string>();
}

bool ObjectReader::boolean(std::string_view key, bool fallback) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  if (!value->is_boolean()) fail(key, "true or false", value);
  return value->get<bool>();
}

std::string ObjectReader::choice(std::string_view key, std::string fallback,
                                 std::initializer_list<std::string_view> choices) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  std::string expected = "one of";
  for (std::string_view c : choices) {
    if (value->is_string() && value->get<std::string>() == c) return std::string(c);
    expected += " \"" + std::string(c) + "\"";
  }
  fail(key, expected, value);
}

sim::Vec3 readVec3(const nlohmann::json& value, const std::string& path, const std::string& source, double maxAbs,
                   std::string_view unit) {
  std::ostringstream expected;
  expected.precision(12);
  expected << "[x, y, z]: three numbers within +-" << maxAbs;
  if (!unit.empty()) expected << " (" << unit << ")";
  if (!value.is_array() || value.size() != 3) failAt(source, path, expected.str(), &value);
  sim::Vec3 v;
  for (int i = 0; i < 3; ++i) {
    const nlohmann::json& component = value[static_cast<std::size_t>(i)];
    const double x = component.is_number() ? component.get<double>() : NAN;
    if (!std::isfinite(x) || std::abs(x) > maxAbs) failAt(source, path, expected.str(), &value);
    v[i] = x;
  }
  return v;
}

sim::Vec3 ObjectReader::vec3(std::string_view key, sim::Vec3 fallback, double maxAbs, std::string_view unit) {
  const nlohmann::json* value = find(key);
  if (!value) return fallback;
  return readVec3(*value, pathOf(key), source_, maxAbs, unit);
}

ObjectReader ObjectReader::object(std::string_view key) {
  const nlohmann::json* value = find(key);
  if (!value) fail(key, "an object { ... }", nullptr);
  return ObjectReader(*value, pathOf(key), source_);
}

const nlohmann::json& ObjectReader::array(std::string_view key, std::size_t maxSize) {
  static const nlohmann::json empty = nlohmann::json::array();
  const nlohmann::json* value = find(key);
  if (!value) return empty;
  if (!value->is_array() || value->size() > maxSize) {
    fail(key, "an array of at most " + std::to_string(maxSize) + " elements", value);
  }
  return *value;
}

void ObjectReader::finish() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!read_.contains(it.key())) {
      throw InputError(source_ + ": " + pathOf(printable(it.key())) + ": unknown key");
    }
  }
}

json readJsonFile(const std::filesystem::path& file, std::string_view what, std::size_t maxBytes) {
  return parseJson(readInputFile(file, what, maxBytes), printable(file.string(), 200));
}

}  // namespace drape::scene
