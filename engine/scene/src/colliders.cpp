#include "colliders.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <tiny_obj_loader.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/input.hpp"
#include "drape/scene/obj.hpp"

namespace drape::scene {

namespace {

glm::dquat fromDegrees(sim::Vec3 degrees) { return glm::dquat(degrees * kDegrees); }  // Euler x, y, z

std::shared_ptr<const sim::TriangleMesh> loadObj(ObjectReader& reader, const std::string& sceneSource, double scale) {
  const std::string file = reader.text("file", "");
  if (file.empty()) reader.fail("file", "the path of an OBJ file (relative to the scene file)", reader.raw("file"));
  const std::filesystem::path path = std::filesystem::path(sceneSource).parent_path() / file;
  const std::string what =
      reader.source() + ": " + reader.pathOf("file") + ": cannot use the OBJ file " + printable(path.string(), 200);
  std::string text;
  try {
    text = readInputFile(path, "OBJ file", kMaxMeshFileBytes);
  } catch (const InputError& error) {
    // "PATH: cannot open the OBJ file: WHY" -> "SCENE: KEY: cannot use the OBJ file PATH: WHY"
    const std::string message = error.what();
    const std::size_t why = message.find("OBJ file: ");
    throw InputError(what + ": " + (why == std::string::npos ? message : message.substr(why + 10)));
  }
  return parseObj(text, what, scale);
}

}  // namespace

std::shared_ptr<const sim::TriangleMesh> parseObj(std::string_view text, const std::string& what, double scale) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader obj;
  // From memory, with an empty material library: an `mtllib` line names nothing we open.
  if (!obj.ParseFromString(std::string(text), "", config)) {
    std::string why = obj.Error();
    for (char& ch : why) ch = ch == '\n' ? ' ' : ch;
    throw InputError(what + ": " + printable(why, 200));
  }
  auto mesh = std::make_shared<sim::TriangleMesh>();
  const std::vector<tinyobj::real_t>& v = obj.GetAttrib().vertices;
  mesh->vertices.reserve(v.size() / 3);
  for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
    const sim::Vec3 p = sim::Vec3{v[i], v[i + 1], v[i + 2]} * scale;
    // Beyond this the collider's grid could not hold the mesh (and no scene reaches it).
    if (!(std::abs(p.x) <= kMaxMeshCoordinate && std::abs(p.y) <= kMaxMeshCoordinate &&
          std::abs(p.z) <= kMaxMeshCoordinate)) {
      throw InputError(what + ": vertex " + std::to_string(i / 3 + 1) + " lies beyond +-" +
                       std::to_string(static_cast<int>(kMaxMeshCoordinate)) + " m (after scale), or is not finite");
    }
    mesh->vertices.push_back(p);
  }
  const auto count = static_cast<long long>(mesh->vertices.size());
  for (const tinyobj::shape_t& shape : obj.GetShapes()) {
    const auto& indices = shape.mesh.indices;
    for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
      const long long a = indices[i].vertex_index, b = indices[i + 1].vertex_index, c = indices[i + 2].vertex_index;
      if (a < 0 || b < 0 || c < 0 || a >= count || b >= count || c >= count) {
        throw InputError(what + ": a face refers to a vertex it does not have");
      }
      if (mesh->triangles.size() == kMaxMeshTriangles) {
        throw InputError(what + ": it has more than " + std::to_string(kMaxMeshTriangles) + " triangles");
      }
      mesh->triangles.emplace_back(a, b, c);
    }
  }
  if (mesh->triangles.empty()) throw InputError(what + ": it has no triangles");
  return mesh;
}

sim::ColliderSettings readCollider(ObjectReader& reader, const std::string& sceneSource) {
  sim::ColliderSettings c;
  const std::string type = reader.choice("type", "", {"plane", "sphere", "capsule", "box", "mesh"});
  if (type.empty()) reader.fail("type", "one of \"plane\" \"sphere\" \"capsule\" \"box\" \"mesh\"", nullptr);
  const Range radius{0.0, 1000.0, true, "m"};
  if (type == "plane") {
    c.shape = sim::ColliderShape::plane;
    c.position = reader.vec3("point", sim::Vec3{0.0}, kMaxCoordinate, "m");
    c.normal = reader.vec3("normal", sim::Vec3{0.0, 1.0, 0.0}, 1.0e6, "");
    if (!(glm::length(c.normal) > 1e-9)) reader.fail("normal", "a non-zero vector", reader.raw("normal"));
  } else if (type == "sphere") {
    c.shape = sim::ColliderShape::sphere;
    c.position = reader.vec3("centre", sim::Vec3{0.0}, kMaxCoordinate, "m");
    c.radius = reader.number("radius", 0.5, radius);
  } else if (type == "capsule") {
    c.shape = sim::ColliderShape::capsule;
    const sim::Vec3 from = reader.vec3("from", sim::Vec3{-0.5, 0.0, 0.0}, kMaxCoordinate, "m");
    const sim::Vec3 to = reader.vec3("to", sim::Vec3{0.5, 0.0, 0.0}, kMaxCoordinate, "m");
    c.position = (from + to) * 0.5;
    c.halfAxis = (to - from) * 0.5;
    c.radius = reader.number("radius", 0.1, radius);
  } else if (type == "box") {
    c.shape = sim::ColliderShape::box;
    c.position = reader.vec3("centre", sim::Vec3{0.0}, kMaxCoordinate, "m");
    c.halfExtents = reader.vec3("halfExtents", sim::Vec3{0.5}, 1000.0, "m");
    if (!glm::all(glm::greaterThan(c.halfExtents, sim::Vec3{0.0}))) {
      reader.fail("halfExtents", "three positive numbers (m)", reader.raw("halfExtents"));
    }
    c.rounding = reader.number("rounding", 0.0, {0.0, 1000.0, false, "m"});
    if (c.rounding > std::min({c.halfExtents.x, c.halfExtents.y, c.halfExtents.z})) {
      reader.fail("rounding", "at most the smallest half extent (m)", reader.raw("rounding"));
    }
    c.orientation = fromDegrees(reader.vec3("rotation", sim::Vec3{0.0}, 3600.0, "degrees about x, y, z"));
  } else {
    c.shape = sim::ColliderShape::mesh;
    c.position = reader.vec3("translate", sim::Vec3{0.0}, kMaxCoordinate, "m");
    c.orientation = fromDegrees(reader.vec3("rotation", sim::Vec3{0.0}, 3600.0, "degrees about x, y, z"));
    c.mesh = loadObj(reader, sceneSource, reader.number("scale", 1.0, {0.0, 1000.0, true, ""}));
  }
  if (reader.has("friction")) {
    ObjectReader friction = reader.object("friction");
    c.friction.staticCoefficient = friction.number("static", 0.5, {0.0, 10.0, false, ""});
    c.friction.kineticCoefficient =
        friction.number("kinetic", c.friction.staticCoefficient * 0.8, {0.0, 10.0, false, ""});
    friction.finish();
  }
  c.velocity = reader.vec3("velocity", sim::Vec3{0.0}, 1000.0, "m/s");
  c.angularVelocity = reader.vec3("angularVelocity", sim::Vec3{0.0}, 36000.0, "degrees/s") * kDegrees;
  reader.finish();
  return c;
}

sim::SelfCollisionSettings readSelfCollision(ObjectReader& reader) {
  sim::SelfCollisionSettings s;
  s.enabled = reader.boolean("enabled", true);
  s.method = *sim::parseSelfContactMethod(reader.choice("method", "triangles", {"triangles", "particles"}));
  s.distance = reader.number("distance", s.distance, {1.0e-4, 1.0, false, "m"});
  s.friction = reader.number("friction", s.friction, {0.0, 1.0, false, "share of relative velocity removed"});
  s.maxTravel = reader.number("maxTravel", s.maxTravel, {0.01, 10.0, false, "distances per substep"});
  reader.finish();
  return s;
}

}  // namespace drape::scene
