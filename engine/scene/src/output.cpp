#include "drape/scene/output.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::scene {

namespace {

std::filesystem::path temporaryName(const std::filesystem::path& file) {
  std::filesystem::path temporary = file;
  temporary += ".part";
  return temporary;
}

void removeTemporaries(const std::vector<OutputFile>& files, std::size_t count) {
  std::error_code ignored;
  for (std::size_t i = 0; i < count; ++i) std::filesystem::remove(temporaryName(files[i].path), ignored);
}

}  // namespace

void writeFilesAtomically(const std::vector<OutputFile>& files) {
  namespace fs = std::filesystem;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path& file = files[i].path;
    const std::string name = file.string();
    std::error_code error;
    std::string problem;
    if (file.filename().empty()) {
      problem = "not a file name";
    } else if (fs::is_directory(file, error)) {
      problem = "it is a directory";
    } else {
      std::ofstream out(temporaryName(file), std::ios::binary | std::ios::trunc);
      if (!out) {
        problem = "the directory is missing or not writable";
      } else {
        out.write(files[i].contents.data(), static_cast<std::streamsize>(files[i].contents.size()));
        out.flush();
        if (!out) problem = "the write failed (disk full?)";
      }
    }
    if (!problem.empty()) {
      removeTemporaries(files, i + 1);
      throw InputError(name + ": cannot write: " + problem);
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code error;
    fs::rename(temporaryName(files[i].path), files[i].path, error);
    if (error) {
      removeTemporaries(files, files.size());
      throw InputError(files[i].path.string() + ": cannot write: " + error.message());
    }
  }
}

void writeFileAtomically(const std::filesystem::path& file, std::string_view contents) {
  writeFilesAtomically({{file, std::string(contents)}});
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
  document["metrics"] = {{"strain", {{"max", strain.max}, {"mean", strain.mean}, {"constraints", strain.count}}},
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
