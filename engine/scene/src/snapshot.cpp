#include "drape/scene/snapshot.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "json_reader.hpp"

namespace drape::scene {

namespace {

using nlohmann::json;
constexpr int kFormat = 1;

json vectors(const std::vector<sim::Vec3>& values) {
  json array = json::array();
  for (const sim::Vec3& v : values) array.push_back({v.x, v.y, v.z});
  return array;
}

// Reads an array of n-tuples of numbers at `key`, each checked by `check`.
template <typename T, typename Make>
std::vector<T> tuples(ObjectReader& reader, std::string_view key, std::size_t width, std::string_view expected,
                      Make make) {
  std::vector<T> result;
  const json& array = reader.array(key, sim::kMaxParticles * 8);
  result.reserve(array.size());
  for (std::size_t i = 0; i < array.size(); ++i) {
    const json& item = array[i];
    bool ok = width == 1 ? item.is_number() : item.is_array() && item.size() == width;
    for (std::size_t k = 0; ok && width > 1 && k < width; ++k) ok = item[k].is_number();
    std::optional<T> made;
    if (ok) made = make(item);
    if (!made) failAt(reader.source(), reader.pathOf(key) + "." + std::to_string(i), expected, &item);
    result.push_back(*made);
  }
  return result;
}

std::optional<sim::Vec3> vec3(const json& item) {
  const sim::Vec3 v{item[0].get<double>(), item[1].get<double>(), item[2].get<double>()};
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return std::nullopt;
  return v;
}

}  // namespace

json snapshotDocument(const Scene& scene, const sim::World& world) {
  json cloths = json::array();
  for (const sim::Cloth& cloth : world.cloths()) {
    json c;
    // In double, as the engine's origin plus offset: set again, they give back the same origin (the
    // first particle's, offset 0) and offsets, bit for bit (tested).
    std::vector<sim::Vec3> restPositions(cloth.rest.particleCount());
    for (std::size_t i = 0; i < restPositions.size(); ++i) restPositions[i] = cloth.rest.restPosition(i);
    c["restPositions"] = vectors(restPositions);
    json triangles = json::array();
    for (const glm::uvec3& t : cloth.rest.triangles) triangles.push_back({t.x, t.y, t.z});
    c["triangles"] = std::move(triangles);
    for (sim::ConstraintKind kind : sim::kConstraintKinds) {
      json list = json::array();
      for (const sim::DistanceConstraint& k : cloth.rest.of(kind)) list.push_back({k.a, k.b, k.restLength});
      c[std::string(sim::name(kind))] = std::move(list);
    }
    c["positions"] = vectors(cloth.state.position);
    c["previousPositions"] = vectors(cloth.state.previousPosition);
    if (!cloth.state.velocity.empty()) c["velocities"] = vectors(cloth.state.velocity);
    c["masses"] = cloth.state.mass;
    json pinned = json::array();
    for (std::size_t i = 0; i < cloth.state.pinned.size(); ++i) {
      if (cloth.state.pinned[i]) pinned.push_back(i);
    }
    c["pinned"] = std::move(pinned);
    c["tetherPins"] = cloth.tetherPins;
    // With a stretch target, the links' tension the next step's geometric stiffness reads (floats:
    // a double holds each exactly, and reads back the same).
    if (!cloth.stretchTension.empty()) c["stretchTension"] = cloth.stretchTension;
    c["lattice"] = {cloth.rest.columns, cloth.rest.rows};
    // The spacing it was made with: a drawn cloth's settings here no longer hold its mesh.
    if (cloth.spacing > 0.0) c["spacing"] = cloth.spacing;
    cloths.push_back(std::move(c));
  }
  return {{"drapeSnapshot", kFormat},
          {"time", world.time()},
          {"scene", json::parse(scene.document)},
          {"cloths", std::move(cloths)}};
}

Snapshot loadSnapshot(const std::filesystem::path& file) {
  return parseSnapshot(readJsonFile(file, "snapshot", kMaxSnapshotFileBytes), file.string());
}

Snapshot parseSnapshot(const nlohmann::json& document, const std::string& source) {
  ObjectReader root(document, "", source);
  if (!root.has("drapeSnapshot")) {
    // A scene (or a state) under a snapshot's name (NAME.drape.json): said as what it is not.
    throw InputError(source +
                     ": not a snapshot (no \"drapeSnapshot\" key): a name ending in .drape.json is a snapshot's, a "
                     "scene file's ends in .json alone");
  }
  if (root.integer("drapeSnapshot", 0, kFormat, kFormat) != kFormat) root.fail("drapeSnapshot", "1", nullptr);
  Snapshot snapshot;
  snapshot.time = root.number("time", 0.0, {0.0, 1.0e9, false, "s"});
  const json* sceneDocument = root.raw("scene");
  if (!sceneDocument) root.fail("scene", "the scene's document", nullptr);
  snapshot.scene = parseScene(*sceneDocument, source + " (scene)");
  snapshot.scene.source = source;
  const json& cloths = root.array("cloths", 64);
  const sim::ClothSettings drawn = drawnClothTemplate(snapshot.scene);
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    ObjectReader reader(cloths[c], "cloths." + std::to_string(c), source);
    sim::Cloth cloth;
    cloth.settings = c < snapshot.scene.world.cloths.size() ? snapshot.scene.world.cloths[c] : drawn;
    // The mesh below is the cloth; a drawn cloth's mesh, pins and weights were for building it.
    cloth.settings.mesh.reset();
    cloth.settings.pins.clear();
    cloth.settings.masses.clear();
    try {
      cloth.rest.setRestPositions(tuples<sim::Vec3>(reader, "restPositions", 3, "[x, y, z], finite", vec3));
    } catch (const std::invalid_argument& error) {
      throw InputError(source + ": " + reader.pathOf("restPositions") + ": " + error.what());
    }
    const std::size_t n = cloth.rest.particleCount();
    const auto index = [n](const json& v) -> std::optional<std::uint32_t> {
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= static_cast<long long>(n)) {
        return std::nullopt;
      }
      return static_cast<std::uint32_t>(v.get<long long>());
    };
    const std::string particle = "a particle index below " + std::to_string(n);
    cloth.rest.triangles = tuples<glm::uvec3>(reader, "triangles", 3, "[a, b, c], " + particle,
                                              [&](const json& t) -> std::optional<glm::uvec3> {
                                                const auto a = index(t[0]), b = index(t[1]), d = index(t[2]);
                                                if (!a || !b || !d) return std::nullopt;
                                                return glm::uvec3{*a, *b, *d};
                                              });
    for (sim::ConstraintKind kind : sim::kConstraintKinds) {
      cloth.rest.constraints[static_cast<std::size_t>(kind)] = tuples<sim::DistanceConstraint>(
          reader, sim::name(kind), 3, "[a, b, rest length], " + particle,
          [&](const json& k) -> std::optional<sim::DistanceConstraint> {
            const auto a = index(k[0]), b = index(k[1]);
            if (!a || !b || *a == *b) return std::nullopt;
            try {
              return sim::DistanceConstraint{*a, *b, sim::toRestLength(k[2].get<double>())};
            } catch (const std::invalid_argument&) {
              return std::nullopt;  // not one a float holds
            }
          });
    }
    sim::ParticleState& s = cloth.state;
    s.position = tuples<sim::Vec3>(reader, "positions", 3, "[x, y, z], finite", vec3);
    s.previousPosition = tuples<sim::Vec3>(reader, "previousPositions", 3, "[x, y, z], finite", vec3);
    if (reader.has("velocities")) s.velocity = tuples<sim::Vec3>(reader, "velocities", 3, "[x, y, z], finite", vec3);
    s.mass = tuples<sim::MassReal>(reader, "masses", 1, "a mass in kg, 1.2e-38 to 3.4e38",
                                   [](const json& m) -> std::optional<sim::MassReal> {
                                     try {
                                       return sim::toMass(m.get<double>());
                                     } catch (const std::invalid_argument&) {
                                       return std::nullopt;  // not one a float holds
                                     }
                                   });
    s.pinned.assign(n, 0);
    for (std::uint32_t p : tuples<std::uint32_t>(reader, "pinned", 1, particle, index)) s.pinned[p] = 1;
    // The pins the tethers go to (the cloth's own, not those pinned by hand); a snapshot without
    // them ties every pin.
    if (reader.has("tetherPins")) {
      cloth.tetherPins = tuples<std::uint32_t>(reader, "tetherPins", 1, particle, index);
    } else {
      for (std::uint32_t p = 0; p < n; ++p) {
        if (s.pinned[p]) cloth.tetherPins.push_back(p);
      }
    }
    if (reader.has("stretchTension")) {
      cloth.stretchTension = tuples<float>(reader, "stretchTension", 1, "a finite number of N s^2, as a float holds it",
                                           [](const json& t) -> std::optional<float> {
                                             if (!t.is_number()) return std::nullopt;
                                             const double v = t.get<double>();
                                             if (!(std::abs(v) <= std::numeric_limits<float>::max()))
                                               return std::nullopt;
                                             return static_cast<float>(v);
                                           });
      const std::size_t links = cloth.rest.of(sim::ConstraintKind::stretch).size();
      if (cloth.stretchTension.size() != links) {
        reader.fail("stretchTension", "one entry per stretch constraint (" + std::to_string(links) + ")",
                    reader.raw("stretchTension"));
      }
    }
    s.inverseMass.assign(n, 0.0);
    const json* lattice = reader.raw("lattice");
    if (lattice && lattice->is_array() && lattice->size() == 2 && (*lattice)[0].is_number_integer() &&
        (*lattice)[1].is_number_integer()) {
      cloth.rest.columns = (*lattice)[0].get<int>();
      cloth.rest.rows = (*lattice)[1].get<int>();
    }
    if (cloth.rest.columns < 0 || cloth.rest.rows < 0 ||
        static_cast<long long>(cloth.rest.columns) * cloth.rest.rows > static_cast<long long>(n)) {
      reader.fail("lattice", "[columns, rows] of the lattice the first particles came from", lattice);
    }
    // (Older snapshots have none: the spacing then comes from the settings, as it did.)
    cloth.spacing = reader.number("spacing", 0.0, {0.0, 1.0e3, false, "m"});
    reader.finish();
    if (s.position.size() != n || s.previousPosition.size() != n || s.mass.size() != n) {
      throw InputError(source + ": " + reader.pathOf("positions") + ": positions, previousPositions and masses need " +
                       std::to_string(n) + " entries each, one per rest position");
    }
    snapshot.cloths.push_back(std::move(cloth));
  }
  root.finish();
  return snapshot;
}

bool isSnapshotName(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  constexpr std::string_view kTail = ".drape.json";
  return name.size() > kTail.size() && name.compare(name.size() - kTail.size(), kTail.size(), kTail) == 0;
}

sim::World makeWorld(const Snapshot& snapshot) {
  try {
    sim::WorldSettings settings = snapshot.scene.world;
    settings.cloths.clear();
    sim::World world(settings);
    std::vector<sim::Cloth> cloths = snapshot.cloths;
    if (settings.solver.model == sim::Model::force) {
      for (sim::Cloth& cloth : cloths) {
        if (cloth.state.velocity.empty()) cloth.state.velocity.assign(cloth.state.position.size(), sim::Vec3{0.0});
      }
    } else {
      for (sim::Cloth& cloth : cloths) cloth.state.velocity.clear();
    }
    world.restoreCloths(std::move(cloths));
    // The clock where it was saved: a moving collider (rising-sphere's ball) goes on from there.
    world.restoreStepCount(std::llround(snapshot.time / settings.solver.dt));
    return world;
  } catch (const std::invalid_argument& error) {
    throw InputError(snapshot.scene.source + ": " + error.what());
  }
}

}  // namespace drape::scene
