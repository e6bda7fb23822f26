#include "drape/scene/scene.hpp"
#include "drape/scene/fabric.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "colliders.hpp"
#include "drape/mesh/outline.hpp"
#include "drape/scene/error.hpp"
#include "drape/sim/world.hpp"
#include "json_reader.hpp"

namespace drape::scene {

namespace {

using nlohmann::json;
using sim::ConstraintKind;
using sim::KindMaterial;
using sim::Model;

constexpr int kMaxCloths = 64;
constexpr int kMaxColliders = 256;
constexpr std::size_t kMaxPins = 100000;

// Defaults per model: the position model's 0..1 stiffnesses, and the force model's springs in N/m
// and N s/m (sized for a ~1 kg sheet of a few hundred particles).
KindMaterial defaultMaterial(Model model, ConstraintKind kind) {
  if (model == Model::position) {
    switch (kind) {
      case ConstraintKind::stretch: return {1.0, 0.0};
      case ConstraintKind::shear: return {1.0, 0.0};
      case ConstraintKind::bend: return {0.2, 0.0};
    }
  }
  switch (kind) {
    case ConstraintKind::stretch: return {2000.0, 1.0};
    case ConstraintKind::shear: return {2000.0, 1.0};
    case ConstraintKind::bend: return {200.0, 0.1};
  }
  return {};
}

KindMaterial readMaterial(ObjectReader& cloth, ConstraintKind kind, Model model, bool xpbd) {
  KindMaterial material = defaultMaterial(model, kind);
  const std::string_view key = sim::name(kind);
  if (!cloth.has(key)) return material;
  ObjectReader reader = cloth.object(key);
  if (model == Model::position) {
    material.stiffness =
        reader.number("stiffness", material.stiffness, {0.0, 1.0, false, "fraction corrected per sweep"});
    material.damping = reader.number("damping", material.damping,
                                     {0.0, 1.0, false, "fraction of relative velocity removed per substep"});
    if (reader.has("compliance") && !xpbd) {
      reader.fail("compliance", "no compliance unless \"solver\": {\"xpbd\": true}", reader.raw("compliance"));
    }
    material.compliance = reader.number("compliance", 0.0, {0.0, 1.0, false, "m/N"});
  } else {
    material.stiffness = reader.number("stiffness", material.stiffness, {0.0, 1.0e9, false, "N/m"});
    material.damping = reader.number("damping", material.damping, {0.0, 1.0e6, false, "N s/m"});
  }
  reader.finish();
  return material;
}

// "fabric": a preset's name, or an object of the four numbers (each optional over "preset", or
// over cotton's). A fabric's mass follows from its area and its materials from its stiffnesses, so
// "mass", "masses" and the kinds' stiffness and compliance keys are refused beside it.
std::optional<sim::Fabric> readFabric(ObjectReader& cloth, Model model) {
  if (!cloth.has("fabric")) return std::nullopt;
  if (model != Model::position) {
    cloth.fail("fabric", "no fabric in the force model (it needs \"model\": \"position\")", cloth.raw("fabric"));
  }
  for (const char* key : {"mass", "masses"}) {
    if (cloth.has(key)) cloth.fail(key, "no \"mass\" beside \"fabric\" (its areal density weighs it)", cloth.raw(key));
  }
  for (ConstraintKind kind : sim::kConstraintKinds) {
    const std::string_view key = sim::name(kind);
    if (cloth.has(key)) {
      cloth.fail(key, "no stretch, shear or bend materials beside \"fabric\" (they follow from it)", cloth.raw(key));
    }
  }
  std::string names;
  for (const FabricPreset& preset : fabricPresets()) names += (names.empty() ? "" : ", ") + std::string(preset.name);
  const json* value = cloth.raw("fabric");
  const auto named = [&](const json& text, const std::string& path) {
    if (!text.is_string() || !fabricPreset(text.get<std::string>())) {
      failAt(cloth.source(), path, "a fabric preset (" + names + ")", &text);
    }
    return *fabricPreset(text.get<std::string>());
  };
  if (value->is_string()) {
    (void)cloth.text("fabric", "");
    return named(*value, cloth.pathOf("fabric"));
  }
  ObjectReader reader = cloth.object("fabric");
  sim::Fabric fabric;  // cotton
  if (reader.has("preset")) {
    fabric = named(*reader.raw("preset"), reader.pathOf("preset"));
    (void)reader.text("preset", "");
  }
  fabric.arealDensity = reader.number("arealDensity", fabric.arealDensity, {1.0e-3, 10.0, false, "kg/m^2"});
  fabric.bendingRigidity = reader.number("bendingRigidity", fabric.bendingRigidity, {1.0e-9, 1.0, false, "N m"});
  fabric.stretchStiffness = reader.number("stretchStiffness", fabric.stretchStiffness, {1.0, 1.0e7, false, "N/m"});
  fabric.shearStiffness = reader.number("shearStiffness", fabric.shearStiffness, {1.0e-2, 1.0e7, false, "N/m"});
  reader.finish();
  return fabric;
}

constexpr std::size_t kMaxOutlinePoints = 100000;

// The lattice particle at `particle`: [column, row] inside the grid.
std::pair<int, int> readParticle(ObjectReader& reader, const sim::LatticeSpec& lattice) {
  const std::string expected =
      "[column, row] inside the " + std::to_string(lattice.columns) + " x " + std::to_string(lattice.rows) + " grid";
  const json* found = reader.raw("particle");
  if (!found) reader.fail("particle", expected, nullptr);
  const json& particle = *found;
  const bool ok = particle.is_array() && particle.size() == 2 && particle[0].is_number_integer() &&
                  particle[1].is_number_integer() && particle[0].get<long long>() >= 0 &&
                  particle[0].get<long long>() < lattice.columns && particle[1].get<long long>() >= 0 &&
                  particle[1].get<long long>() < lattice.rows;
  if (!ok) reader.fail("particle", expected, &particle);
  return {particle[0].get<int>(), particle[1].get<int>()};
}

// A drawn cloth: {"points": [[x, z], ...], "spacing": s, "height": y}.
mesh::OutlineSpec readOutline(ObjectReader& reader) {
  mesh::OutlineSpec outline;
  const json& points = reader.array("points", kMaxOutlinePoints);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const json& p = points[i];
    const bool ok = p.is_array() && p.size() == 2 && p[0].is_number() && p[1].is_number() &&
                    std::abs(p[0].get<double>()) <= kMaxCoordinate && std::abs(p[1].get<double>()) <= kMaxCoordinate;
    if (!ok) {
      failAt(reader.source(), reader.pathOf("points") + "." + std::to_string(i),
             "[x, z] in metres, each within +-" + std::to_string(static_cast<int>(kMaxCoordinate)), &p);
    }
    outline.points.push_back({p[0].get<double>(), p[1].get<double>()});
  }
  outline.spacing = reader.number("spacing", outline.spacing, {1.0e-3, 10.0, false, "m"});
  outline.height = reader.number("height", outline.height, {-kMaxCoordinate, kMaxCoordinate, false, "m"});
  reader.finish();
  return outline;
}

sim::ClothSettings readCloth(ObjectReader& reader, Model model, bool xpbd, long long& particleBudget) {
  sim::ClothSettings cloth;
  if (reader.has("outline")) {
    if (reader.has("grid")) reader.fail("grid", "either \"grid\" or \"outline\", not both", reader.raw("grid"));
    if (reader.has("pins"))
      reader.fail("pins", "no pins on a drawn cloth (they name lattice columns and rows)", reader.raw("pins"));
    ObjectReader outlineReader = reader.object("outline");
    const mesh::OutlineSpec outline = readOutline(outlineReader);
    try {
      mesh::OutlineMesh shape = mesh::meshOutline(outline);
      const auto particles = static_cast<long long>(shape.positions.size());
      if (particles > particleBudget) {
        throw InputError(reader.source() + ": " + reader.pathOf("outline") + ": " + std::to_string(particles) +
                         " particles pass the limit of " + std::to_string(sim::kMaxParticles) +
                         " particles over all cloths");
      }
      particleBudget -= particles;
      cloth.mesh = std::make_shared<const sim::LatticeMesh>(sim::LatticeMesh{
          std::move(shape.positions), std::move(shape.triangles), std::move(shape.nodes), outline.spacing});
    } catch (const std::invalid_argument& error) {
      throw InputError(reader.source() + ": " + reader.pathOf("outline") + ": " + error.what());
    }
    cloth.fabric = readFabric(reader, model);
    cloth.mass = reader.number("mass", 1.0, {1.0e-6, 1.0e6, false, "kg"});
    cloth.initialVelocity = reader.vec3("velocity", sim::Vec3{0.0}, 1000.0, "m/s");
    cloth.initialSpin = reader.vec3("spin", sim::Vec3{0.0}, 36000.0, "degrees/s") * kDegrees;
    cloth.thickness = reader.number("thickness", cloth.thickness, {1.0e-4, 0.1, false, "m"});
    for (ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = readMaterial(reader, kind, model, xpbd);
    reader.finish();
    return cloth;
  }
  ObjectReader grid = reader.object("grid");
  sim::LatticeSpec& lattice = cloth.lattice;
  lattice.columns = grid.integer("columns", 2, 1, sim::kMaxLatticeSide);
  lattice.rows = grid.integer("rows", 2, 1, sim::kMaxLatticeSide);
  lattice.width = grid.number("width", 1.0, {0.0, 1000.0, true, "m"});
  lattice.height = grid.number("height", 1.0, {0.0, 1000.0, true, "m"});
  const long long particles = static_cast<long long>(lattice.columns) * lattice.rows;
  if (particles > particleBudget) {
    throw InputError(reader.source() + ": " + reader.pathOf("grid") + ": " + std::to_string(lattice.columns) + " x " +
                     std::to_string(lattice.rows) + " particles pass the limit of " +
                     std::to_string(sim::kMaxParticles) + " particles over all cloths");
  }
  particleBudget -= particles;
  grid.finish();

  lattice.origin = reader.vec3("origin", sim::Vec3{0.0}, kMaxCoordinate, "m");
  lattice.plane = reader.choice("plane", "xz", {"xz", "xy"}) == "xz" ? sim::LatticePlane::xz : sim::LatticePlane::xy;
  cloth.fabric = readFabric(reader, model);
  if (cloth.fabric && (lattice.columns < 2 || lattice.rows < 2)) {
    reader.fail("fabric", "a sheet of at least 2 x 2 particles for a fabric (a chain has no area)",
                reader.raw("fabric"));
  }
  cloth.mass = reader.number("mass", 1.0, {1.0e-6, 1.0e6, false, "kg"});
  cloth.initialVelocity = reader.vec3("velocity", sim::Vec3{0.0}, 1000.0, "m/s");
  cloth.initialSpin = reader.vec3("spin", sim::Vec3{0.0}, 36000.0, "degrees/s") * kDegrees;
  cloth.thickness = reader.number("thickness", cloth.thickness, {1.0e-4, 0.1, false, "m"});
  for (ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = readMaterial(reader, kind, model, xpbd);

  const json& pins = reader.array("pins", kMaxPins);
  for (std::size_t i = 0; i < pins.size(); ++i) {
    ObjectReader pin(pins[i], reader.pathOf("pins") + "." + std::to_string(i), reader.source());
    const auto [column, row] = readParticle(pin, lattice);
    sim::Pin result{column, row, std::nullopt};
    if (pin.has("position")) result.position = pin.vec3("position", sim::Vec3{0.0}, kMaxCoordinate, "m");
    pin.finish();
    cloth.pins.push_back(result);
  }
  const json& masses = reader.array("masses", kMaxPins);
  for (std::size_t i = 0; i < masses.size(); ++i) {
    ObjectReader weight(masses[i], reader.pathOf("masses") + "." + std::to_string(i), reader.source());
    const auto [column, row] = readParticle(weight, lattice);
    if (!weight.has("mass")) weight.fail("mass", "the particle's mass in kg", nullptr);
    const double mass = weight.number("mass", 1.0, {1.0e-9, 1.0e9, false, "kg"});
    weight.finish();
    cloth.masses.push_back({column, row, mass});
  }
  reader.finish();
  return cloth;
}

}  // namespace

Scene parseScene(const json& document, const std::string& source) {
  Scene scene;
  scene.source = source;
  scene.document = document.dump(-1, ' ', false, json::error_handler_t::replace);
  ObjectReader root(document, "", source);
  // What drape-cli and the app write, given where a scene goes: said as what it is, not as the
  // first scene key it lacks.
  if (root.has("drapeSnapshot")) {
    throw InputError(source +
                     ": a snapshot, not a scene: the app and drape-cli open it as one under a name ending in "
                     ".drape.json");
  }
  if (root.has("steps") && root.has("metrics") && root.has("cloths") && !root.has("duration")) {
    throw InputError(source +
                     ": a state drape-cli wrote (the positions alone), not a scene: `--out NAME.drape.json` writes "
                     "a snapshot the app opens");
  }
  scene.name = root.text("name", std::filesystem::path(source).stem().string());
  scene.description = root.text("description", "");
  scene.duration = root.number("duration", 5.0, {0.0, 1.0e5, true, "s"});

  sim::WorldSettings& world = scene.world;
  if (root.has("solver")) {
    ObjectReader solver = root.object("solver");
    world.solver.model = *sim::parseModel(solver.choice("model", "position", {"position", "force"}));
    world.solver.integrator = *sim::parseIntegrator(
        solver.choice("integrator", "verlet", {"explicit-euler", "symplectic-euler", "verlet", "midpoint", "rk4"}));
    world.solver.dt = solver.number("dt", world.solver.dt, {1.0e-6, 1.0, false, "s"});
    world.solver.substeps = solver.integer("substeps", world.solver.substeps, 1, sim::kMaxSubsteps);
    world.solver.iterations = solver.integer("iterations", world.solver.iterations, 0, sim::kMaxIterations);
    world.solver.damping = solver.number("damping", 0.0, {0.0, 1000.0, false, "1/s"});
    world.solver.xpbd = solver.boolean("xpbd", false);
    world.solver.tethers = solver.boolean("tethers", false);
    // Keys of older scene files, said in the keys that took their place.
    if (solver.has("lines"))
      solver.fail("lines", "\"stretchSolver\": \"lines\" or \"gauss-seidel\" instead", solver.raw("lines"));
    for (const char* old : {"geometricStiffness", "tethersBetweenSteps", "extraLineSteps", "stretchTolerance"}) {
      if (solver.has(old)) {
        solver.fail(old, "\"maxStretch\" instead (the engine picks what works to it: docs/scenes.md)", solver.raw(old));
      }
    }
    world.solver.stretchSolver =
        *sim::parseStretchSolver(solver.choice("stretchSolver", "gauss-seidel", {"gauss-seidel", "lines"}));
    world.solver.maxStretch = solver.number("maxStretch", 0.0, {0.0, 1.0, false, "fraction of the rest length"});
    world.solver.fabricSubstepSpeed =
        solver.number("fabricSubstepSpeed", world.solver.fabricSubstepSpeed, {0.0, 1.0e4, false, "m/s"});
    // Keys that do not go with the others (the engine's one rule for it: sim::conflict).
    if (const std::optional<sim::SolverConflict> c = sim::conflict(world.solver)) {
      const std::string key(c->key);
      try {
        solver.fail(key, c->value, solver.raw(key));
      } catch (const InputError& error) {
        throw KeyConflict(error.what());
      }
    }
    solver.finish();
  }
  world.gravity = root.vec3("gravity", world.gravity, 1000.0, "m/s^2");
  if (root.has("wind")) {
    ObjectReader wind = root.object("wind");
    world.air.velocity = wind.vec3("velocity", sim::Vec3{0.0}, 1000.0, "m/s");
    world.air.drag = wind.number("drag", 0.0, {0.0, 1000.0, false, "1/s"});
    world.air.pressure = wind.number("pressure", 0.0, {0.0, 1.0e4, false, "kg/(m^2 s)"});
    wind.finish();
  }
  const json& colliders = root.array("colliders", kMaxColliders);
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    ObjectReader collider(colliders[i], "colliders." + std::to_string(i), source);
    world.colliders.push_back(readCollider(collider, source));
  }
  if (root.has("tearing")) {
    ObjectReader tearing = root.object("tearing");
    world.tearing.enabled = tearing.boolean("enabled", true);
    world.tearing.threshold =
        tearing.number("threshold", world.tearing.threshold, {1.0, 100.0, true, "ratio to the rest length"});
    tearing.finish();
  }
  if (root.has("selfCollision")) {
    ObjectReader self = root.object("selfCollision");
    world.selfCollision = readSelfCollision(self);
  }
  const json& cloths = root.array("cloths", kMaxCloths);
  long long particleBudget = sim::kMaxParticles;
  for (std::size_t i = 0; i < cloths.size(); ++i) {
    ObjectReader cloth(cloths[i], "cloths." + std::to_string(i), source);
    world.cloths.push_back(readCloth(cloth, world.solver.model, world.solver.xpbd, particleBudget));
  }
  root.finish();
  return scene;
}

namespace {

// Levels of objects and arrays in `value` (0 for a number or string). The value was parsed within
// kMaxJsonDepth, so the recursion is bounded.
int depthOf(const json& value) {
  int deepest = 0;
  if (value.is_structured()) {
    for (const json& element : value) deepest = std::max(deepest, depthOf(element));
    return deepest + 1;
  }
  return 0;
}

}  // namespace

void applyOverride(json& document, std::string_view assignment) {
  const std::string where = "--set " + printable(assignment, 120);
  const std::size_t equals = assignment.find('=');
  if (equals == std::string_view::npos || equals == 0) {
    throw InputError(where + ": expected path=value, e.g. cloths.0.grid.columns=64");
  }
  const std::string_view path = assignment.substr(0, equals);
  const std::string_view valueText = assignment.substr(equals + 1);
  // JSON where it is JSON (as strictly as a file: no key twice, no deep nesting), else a string.
  const json value = json::accept(valueText) ? parseJson(valueText, where) : json(std::string(valueText));
  // The path's keys nest the value as deep as a file's objects would: the same limit.
  const auto segments = static_cast<int>(std::count(path.begin(), path.end(), '.')) + 1;
  if (segments + depthOf(value) > kMaxJsonDepth) {
    throw InputError(where + ": nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
  }

  json* node = &document;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    const std::string_view segment =
        path.substr(begin, dot == std::string_view::npos ? path.size() - begin : dot - begin);
    if (segment.empty()) throw InputError(where + ": empty key in the path");
    json* next = nullptr;
    if (node->is_array()) {
      std::size_t index = 0;
      const auto [end, error] = std::from_chars(segment.data(), segment.data() + segment.size(), index);
      if (error != std::errc{} || end != segment.data() + segment.size() || index >= node->size()) {
        throw InputError(where + ": " + printable(segment) + " is not an index of an array of " +
                         std::to_string(node->size()));
      }
      next = &(*node)[index];
    } else if (node->is_object() || node->is_null()) {
      next = &(*node)[std::string(segment)];
    } else {
      throw InputError(where + ": cannot go into " + describe(*node) + " at " + printable(segment));
    }
    if (dot == std::string_view::npos) {
      *next = value;
      return;
    }
    node = next;
    begin = dot + 1;
  }
}

Scene withModel(const Scene& scene, sim::Model model, sim::Integrator integrator) {
  Scene changed = scene;
  sim::SolverSettings& solver = changed.world.solver;
  if (model == Model::position) integrator = sim::Integrator::verlet;
  if (solver.model != model) {
    for (sim::ClothSettings& cloth : changed.world.cloths) {
      for (ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = defaultMaterial(model, kind);
    }
  }
  solver.model = model;
  solver.integrator = integrator;
  solver = sim::consistent(solver);
  if (model == Model::force) {
    try {
      const double longest = 0.9 * sim::World(changed.world).stableForceSubstep();
      if (std::isfinite(longest) && longest > 0.0) {
        const double needed = std::min(std::ceil(solver.dt / longest), static_cast<double>(sim::kMaxSubsteps));
        solver.substeps = std::max(solver.substeps, static_cast<int>(needed));
      }
    } catch (const std::invalid_argument&) {
      // Settings no world takes: whoever builds one says why.
    }
  }
  // The document (what a snapshot keeps) says the same: the model, and the materials left to default.
  json document = json::parse(changed.document, nullptr, false);
  if (document.is_object()) {
    json& solverDocument = document["solver"];
    solverDocument["model"] = std::string(sim::name(model));
    solverDocument["integrator"] = std::string(sim::name(integrator));
    solverDocument["substeps"] = solver.substeps;
    if (model == Model::force) {
      solverDocument.erase("xpbd");
      solverDocument.erase("tethers");
      solverDocument.erase("stretchSolver");
      solverDocument.erase("maxStretch");
    }
    if (document.contains("cloths") && document["cloths"].is_array()) {
      for (json& cloth : document["cloths"]) {
        for (ConstraintKind kind : sim::kConstraintKinds) cloth.erase(std::string(sim::name(kind)));
      }
    }
    changed.document = document.dump(-1, ' ', false, json::error_handler_t::replace);
  }
  return changed;
}

Scene withFabric(const Scene& scene, std::string_view name) {
  const std::optional<sim::Fabric> fabric = fabricPreset(name);
  if (!fabric) throw std::invalid_argument("no fabric preset " + std::string(name));
  Scene changed =
      scene.world.solver.model == Model::position ? scene : withModel(scene, Model::position, sim::Integrator::verlet);
  const auto sheet = [](const sim::ClothSettings& cloth) {
    return cloth.mesh || (cloth.lattice.columns >= 2 && cloth.lattice.rows >= 2);
  };
  for (sim::ClothSettings& cloth : changed.world.cloths) {
    if (!sheet(cloth)) continue;
    cloth.fabric = fabric;
    cloth.masses.clear();
  }
  json document = json::parse(changed.document, nullptr, false);
  if (document.is_object() && document.contains("cloths") && document["cloths"].is_array()) {
    json& cloths = document["cloths"];
    for (std::size_t c = 0; c < cloths.size() && c < changed.world.cloths.size(); ++c) {
      if (!cloths[c].is_object() || !sheet(changed.world.cloths[c])) continue;
      for (const char* key : {"mass", "masses"}) cloths[c].erase(key);
      for (ConstraintKind kind : sim::kConstraintKinds) cloths[c].erase(std::string(sim::name(kind)));
      cloths[c]["fabric"] = std::string(name);
    }
    changed.document = document.dump(-1, ' ', false, json::error_handler_t::replace);
  }
  return changed;
}

sim::ClothSettings drawnClothTemplate(const Scene& scene) {
  if (!scene.world.cloths.empty()) {
    sim::ClothSettings cloth = scene.world.cloths.front();
    cloth.pins.clear();
    cloth.masses.clear();
    cloth.mesh.reset();
    cloth.initialVelocity = sim::Vec3{0.0};
    cloth.initialSpin = sim::Vec3{0.0};
    return cloth;
  }
  sim::ClothSettings cloth;
  for (ConstraintKind kind : sim::kConstraintKinds)
    cloth.material(kind) = defaultMaterial(scene.world.solver.model, kind);
  return cloth;
}

std::filesystem::path sceneDirectory() { return std::filesystem::path(DRAPE_ASSET_DIR) / "scenes"; }

std::filesystem::path resolveScenePath(const std::string& nameOrPath) {
  // Never throws: a name the file system refuses (too long, say) is left for the reader to report.
  std::error_code ignored;
  const std::filesystem::path direct(nameOrPath);
  if (std::filesystem::exists(direct, ignored)) return direct;
  if (direct.parent_path().empty()) {
    std::filesystem::path shipped = sceneDirectory() / direct;
    if (!shipped.has_extension()) shipped += ".json";
    if (std::filesystem::exists(shipped, ignored)) return shipped;
  }
  return direct;
}

Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  // A bare name that is neither a file nor a shipped scene says where the shipped ones are listed.
  // (Only where the file system says plainly that it is not there: a name it refuses, too long or
  // in a folder it may not read, is left for the reader to report.)
  std::error_code error;
  const bool there = std::filesystem::exists(file, error);
  if (file.parent_path().empty() && !there && !error) {
    throw InputError(printable(file.string(), 200) +
                     ": cannot open the scene file: it does not exist, nor is it a shipped scene (drape-cli "
                     "scenes lists them)");
  }
  json document = readJsonFile(file, "scene file", kMaxSceneFileBytes);
  for (const std::string& assignment : overrides) applyOverride(document, assignment);
  try {
    return parseScene(document, file.string());
  } catch (const InputError& refused) {
    // A key an override put there (a misspelt one: "nosuch: unknown key") is the override's, not
    // the file's: the message says which --set it came from.
    const std::string message = refused.what(), lead = file.string() + ": ";
    if (message.rfind(lead, 0) != 0) throw;
    const std::string key = message.substr(lead.size(), message.find(": ", lead.size()) - lead.size());
    for (const std::string& assignment : overrides) {
      const std::string path = assignment.substr(0, assignment.find('='));
      if (!key.empty() && (path == key || path.rfind(key + ".", 0) == 0)) {
        const std::string said = message + " (from --set " + printable(assignment, 120) + ")";
        if (dynamic_cast<const KeyConflict*>(&refused)) throw KeyConflict(said);  // (a study skips those)
        throw InputError(said);
      }
    }
    throw;
  }
}

}  // namespace drape::scene
