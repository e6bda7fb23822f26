#include "drape/scene/output.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::scene {

void writeFileAtomically(const std::filesystem::path& file, std::string_view contents) {
  namespace fs = std::filesystem;
  const std::string name = file.string();
  if (file.filename().empty()) throw InputError(name + ": cannot write: not a file name");
  std::error_code error;
  if (fs::is_directory(file, error)) throw InputError(name + ": cannot write: it is a directory");
  fs::path temporary = file;
  temporary += ".part";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(name + ": cannot write: the directory is missing or not writable");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      out.close();
      fs::remove(temporary, error);
      throw InputError(name + ": cannot write: the write failed (disk full?)");
    }
  }
  fs::rename(temporary, file, error);
  if (error) {
    fs::remove(temporary, error);
    throw InputError(name + ": cannot write: " + error.message());
  }
}

nlohmann::json stateDocument(const Scene& scene, const sim::World& world) {
  using nlohmann::json;
  const sim::StrainStats strain = sim::structuralStrain(world);
  const sim::Energy energy = sim::energy(world);
  json document;
  document["scene"] = scene.name;
  document["source"] = scene.source;
  document["model"] = sim::name(world.settings().solver.model);
  if (world.settings().solver.model == sim::Model::force) {
    document["integrator"] = sim::name(world.settings().solver.integrator);
  }
  document["dt"] = world.settings().solver.dt;
  document["steps"] = world.stepCount();
  document["time"] = world.time();
  document["metrics"] = {
      {"strain", {{"max", strain.max}, {"mean", strain.mean}, {"constraints", strain.count}}},
      {"energy",
       {{"kinetic", energy.kinetic},
        {"gravitational", energy.gravitational},
        {"elastic", energy.elastic},
        {"total", energy.total()}}}};
  json cloths = json::array();
  for (const sim::Cloth& cloth : world.cloths()) {
    json positions = json::array();
    for (const sim::Vec3& x : cloth.state.position) positions.push_back({x.x, x.y, x.z});
    cloths.push_back({{"columns", cloth.rest.columns}, {"rows", cloth.rest.rows}, {"positions", std::move(positions)}});
  }
  document["cloths"] = std::move(cloths);
  return document;
}

std::string objText(const sim::World& world) {
  std::ostringstream out;
  out.precision(9);
  out << "# drape cloth mesh: " << world.cloths().size() << " cloth(s) after " << world.stepCount() << " steps\n";
  std::size_t base = 1;  // OBJ indices start at 1 and run across objects
  for (std::size_t c = 0; c < world.cloths().size(); ++c) {
    const sim::Cloth& cloth = world.cloths()[c];
    out << "o cloth" << c << "\n";
    for (const sim::Vec3& x : cloth.state.position) out << "v " << x.x << ' ' << x.y << ' ' << x.z << "\n";
    for (const sim::Vec3& n : sim::vertexNormals(cloth)) out << "vn " << n.x << ' ' << n.y << ' ' << n.z << "\n";
    for (const glm::uvec3& t : cloth.rest.triangles) {
      out << "f";
      for (int corner = 0; corner < 3; ++corner) out << ' ' << base + t[corner] << "//" << base + t[corner];
      out << "\n";
    }
    if (cloth.rest.triangles.empty()) {  // a chain: its structural links as polyline segments
      for (const sim::DistanceConstraint& link : cloth.rest.of(sim::ConstraintKind::stretch)) {
        out << "l " << base + link.a << ' ' << base + link.b << "\n";
      }
    }
    base += cloth.state.position.size();
  }
  return out.str();
}

}  // namespace drape::scene
