// What a run writes: state files (JSON), meshes (Wavefront OBJ), traces (CSV).
// Files are written to a temporary name beside the target and renamed, so a reader never sees a
// half-written file and a failed run leaves none behind.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "drape/scene/scene.hpp"
#include "drape/sim/world.hpp"

namespace drape::scene {

struct OutputFile {
  std::filesystem::path path;
  std::string contents;
};

// Files written one by one to temporary names beside their targets (each created exclusively,
// never through a link), and renamed into place together by commit(). A batch destroyed before
// commit() removes what it wrote: a failed run leaves the old files as they were. A target that
// is a folder, device, FIFO or socket is refused. add() and commit() throw InputError naming the
// file.
class OutputBatch {
 public:
  OutputBatch() = default;
  OutputBatch(const OutputBatch&) = delete;
  OutputBatch& operator=(const OutputBatch&) = delete;
  ~OutputBatch();
  void add(const std::filesystem::path& file, std::string_view contents);
  // The temporary that will become `file`, created empty, for another program to write.
  std::filesystem::path reserve(const std::filesystem::path& file);
  void commit();

 private:
  struct Entry {
    std::filesystem::path target, temporary;
  };
  std::vector<Entry> entries_;
};

// Writes every file or none: all go to temporary names first, and are renamed into place only
// when all were written. Throws InputError naming the file that could not be written.
void writeFilesAtomically(const std::vector<OutputFile>& files);
void writeFileAtomically(const std::filesystem::path& file, std::string_view contents);

// Positions of every particle (row by row: index = row * columns + column) and the run's metrics.
nlohmann::json stateDocument(const Scene& scene, const sim::World& world);

// Positions, normals and triangles (or line segments for a chain) of every cloth.
std::string objText(const sim::World& world);

}  // namespace drape::scene
