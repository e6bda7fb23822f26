#include "drape/scene/output.hpp"

#include <cerrno>
#include <cstring>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "drape/scene/error.hpp"
#include "drape/scene/input.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::scene {

namespace {

namespace fs = std::filesystem;

std::string reason(int error) {
  switch (error) {
    case ENOENT: return "its folder does not exist";
    case ENOTDIR: return "a folder on its path is a file";
    case EACCES:
    case EPERM: return "permission denied";
    case ENAMETOOLONG: return "the name is too long";
    case ENOSPC: return "the disk is full";
    case EROFS: return "the file system is read-only";
    default: return std::strerror(error);
  }
}

// A new file beside `target` that nobody else has: created exclusively and not through a link
// (O_EXCL fails on any existing name, a planted symbolic link included), named from the target's
// first characters, the process and a counter, so that a name of 255 characters still has room.
struct Temporary {
  fs::path path;
  int fd = -1;
};

Temporary createTemporary(const fs::path& target) {
  static unsigned counter = 0;
  const std::string stem = target.filename().string().substr(0, 64);
  for (int attempt = 0; attempt < 100; ++attempt) {
    Temporary t;
    t.path = target.parent_path() /
             ("." + stem + "." + std::to_string(::getpid()) + "." + std::to_string(counter++) + ".part");
    t.fd = ::open(t.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (t.fd >= 0) return t;
    if (errno != EEXIST) throw InputError(printable(target.string(), 200) + ": cannot write: " + reason(errno));
  }
  throw InputError(printable(target.string(), 200) + ": cannot write: no free temporary name beside it");
}

bool writeAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t done = ::write(fd, bytes.data(), bytes.size());
    if (done < 0 && errno == EINTR) continue;
    if (done <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(done));
  }
  return true;
}

void refuseUnwritable(const std::filesystem::path& file) {
  const std::string name = printable(file.string(), 200);
  struct stat status {};
  const bool exists = ::stat(file.c_str(), &status) == 0;
  if (file.filename().empty() || file.filename() == "." || file.filename() == "..") {
    throw InputError(name + ": cannot write: not a file name");
  }
  if (exists && S_ISDIR(status.st_mode)) throw InputError(name + ": cannot write: it is a folder");
  // Renaming over /dev/null or a FIFO would put a plain file in its place.
  if (exists && !S_ISREG(status.st_mode)) {
    throw InputError(name + ": cannot write: it is not a regular file (a device, FIFO or socket)");
  }
}

}  // namespace

std::filesystem::path OutputBatch::reserve(const std::filesystem::path& file) {
  refuseUnwritable(file);
  const Temporary t = createTemporary(file);
  entries_.push_back({file, t.path});
  ::close(t.fd);
  return t.path;
}

void OutputBatch::add(const std::filesystem::path& file, std::string_view contents) {
  refuseUnwritable(file);
  const std::string name = printable(file.string(), 200);
  Temporary t = createTemporary(file);
  entries_.push_back({file, t.path});
  const bool written = writeAll(t.fd, contents);
  const int writeError = errno;
  const bool closed = ::close(t.fd) == 0;
  if (!written || !closed) throw InputError(name + ": cannot write: " + reason(written ? errno : writeError));
}

void OutputBatch::commit() {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (::rename(entries_[i].temporary.c_str(), entries_[i].target.c_str()) != 0) {
      const int error = errno;
      const std::string name = printable(entries_[i].target.string(), 200);
      entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(i));  // those are in place
      throw InputError(name + ": cannot write: " + reason(error));
    }
  }
  entries_.clear();
}

OutputBatch::~OutputBatch() {
  for (const Entry& e : entries_) ::unlink(e.temporary.c_str());
}

void writeFilesAtomically(const std::vector<OutputFile>& files) {
  OutputBatch batch;
  for (const OutputFile& file : files) batch.add(file.path, file.contents);
  batch.commit();
}

void writeFileAtomically(const std::filesystem::path& file, std::string_view contents) {
  writeFilesAtomically({{file, std::string(contents)}});
}

nlohmann::json stateDocument(const Scene& scene, const sim::World& world) {
  using nlohmann::json;
  const sim::StrainStats strain = sim::structuralStrain(world);
  const sim::Energy energy = sim::energy(world);
  const sim::Momentum momentum = sim::momentum(world);
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
  const sim::IntersectionCount intersections = sim::countIntersections(world);
  const sim::SelfContactStats contact = world.selfContactStats();
  document["metrics"] = {{"strain", {{"max", strain.max}, {"mean", strain.mean}, {"constraints", strain.count}}},
                         {"intersections", {{"pairs", intersections.pairs}, {"skipped", intersections.skipped}}},
                         {"selfContact",
                          {{"pairs", contact.pairs},
                           {"pushed", contact.pushed},
                           {"searches", contact.searches},
                           {"refreshes", contact.refreshes},
                           {"tested", contact.tested},
                           {"triangleTests", contact.triangleTests},
                           {"boxTests", contact.boxTests},
                           {"zoned", contact.zoned},
                           {"fallbacks", contact.fallbacks}}},
                         {"energy",
                          {{"kinetic", energy.kinetic},
                           {"gravitational", energy.gravitational},
                           {"elastic", energy.elastic},
                           {"total", energy.total()}}},
                         {"momentum",
                          {{"linear", {momentum.linear.x, momentum.linear.y, momentum.linear.z}},
                           {"angular", {momentum.angular.x, momentum.angular.y, momentum.angular.z}},
                           {"centre", {momentum.centre.x, momentum.centre.y, momentum.centre.z}}}}};
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
