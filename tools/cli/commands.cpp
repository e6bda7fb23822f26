#include "commands.hpp"

#include "common.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/output.hpp"
#include "drape/scene/scene.hpp"
#include "drape/scene/snapshot.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::cli {

namespace {

std::size_t countConstraints(const sim::World& world) {
  std::size_t count = 0;
  for (const sim::Cloth& cloth : world.cloths()) {
    for (const auto& list : cloth.rest.constraints) count += list.size();
  }
  return count;
}

std::size_t countParticles(const sim::World& world) {
  std::size_t count = 0;
  for (const sim::Cloth& cloth : world.cloths()) count += cloth.rest.particleCount();
  return count;
}

unsigned countPieces(const sim::World& world) {
  unsigned count = 0;
  for (const sim::Cloth& cloth : world.cloths()) count += cloth.pieceCount;
  return count;
}

enum class OutputKind { state, snapshot, mesh };

OutputKind outputKind(const std::string& file) {
  // A snapshot is what the app's save writes and opens: the scene and every cloth whole.
  if (scene::isSnapshotName(file)) return OutputKind::snapshot;
  const std::string extension = std::filesystem::path(file).extension().string();
  if (extension == ".json") return OutputKind::state;
  if (extension == ".obj") return OutputKind::mesh;
  throw scene::InputError("--out " + file +
                          ": expected a file ending in .json (state), .drape.json (a snapshot the app opens) or .obj "
                          "(mesh)");
}

void rejectBadOutputs(const RunArguments& arguments) {
  std::vector<std::string> all = arguments.outputs;
  if (arguments.traceOut) all.push_back(*arguments.traceOut);
  std::vector<std::filesystem::path> seen;
  for (const std::string& file : all) {
    if (file != arguments.traceOut.value_or("")) outputKind(file);
    std::error_code error;
    const std::filesystem::path canonical =
        std::filesystem::weakly_canonical(std::filesystem::absolute(file, error), error);
    if (std::find(seen.begin(), seen.end(), canonical) != seen.end()) {
      throw scene::InputError(file + ": named as an output twice");
    }
    seen.push_back(canonical);
  }
}

struct TraceTarget {
  int cloth;
  sim::ParticleIndex particle;
};

TraceTarget traceTarget(const std::string& text, int cloth, const sim::World& world) {
  const std::string where = "--trace " + text;
  int column = -1, row = -1;
  const std::size_t comma = text.find(',');
  const auto parse = [](std::string_view part, int& value) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    return error == std::errc{} && end == part.data() + part.size();
  };
  if (comma == std::string::npos || !parse(std::string_view(text).substr(0, comma), column) ||
      !parse(std::string_view(text).substr(comma + 1), row)) {
    throw scene::InputError(where + ": expected column,row (two integers)");
  }
  if (cloth >= static_cast<int>(world.cloths().size())) {
    throw scene::InputError("--trace-cloth " + std::to_string(cloth) + ": the scene has " +
                            std::to_string(world.cloths().size()) + " cloth(s)");
  }
  const sim::ClothRest& rest = world.cloths()[static_cast<std::size_t>(cloth)].rest;
  if (column < 0 || column >= rest.columns || row < 0 || row >= rest.rows) {
    throw scene::InputError(where + ": outside the " + std::to_string(rest.columns) + " x " +
                            std::to_string(rest.rows) + " grid of cloth " + std::to_string(cloth));
  }
  return {cloth, rest.index(column, row)};
}

void appendTraceRow(std::ostringstream& csv, const sim::World& world, const TraceTarget& target) {
  const sim::Vec3 x = world.cloths()[static_cast<std::size_t>(target.cloth)].state.position[target.particle];
  csv << world.time() << ',' << x.x << ',' << x.y << ',' << x.z << '\n';
}

}  // namespace

int validate(const SceneArguments& arguments) {
  try {
    const Input input = loadInput(arguments);
    const scene::Scene& scene = input.scene;
    const sim::World world = input.snapshot ? scene::makeWorld(*input.snapshot) : makeWorld(scene);
    std::cout << scene.source << ": ok: \"" << scene.name << "\", " << world.cloths().size() << " cloth(s), "
              << countParticles(world) << " particles, " << countConstraints(world) << " constraints, "
              << sim::name(scene.world.solver.model) << " model\n";
    return kExitOk;
  } catch (const scene::InputError& error) {
    return badInput(error.what());
  }
}

int run(const RunArguments& arguments) {
  try {
    const Input input = loadInput(arguments.input);
    const scene::Scene& scene = input.scene;
    Playback playback(input, arguments.gesture);
    sim::World& world = playback.world();
    rejectBadOutputs(arguments);  // before running, not after
    const std::int64_t steps = stepCount(scene, arguments.steps, arguments.seconds, playback.script());

    std::optional<TraceTarget> target;
    std::ostringstream trace;
    trace.precision(9);
    if (arguments.trace) {
      target = traceTarget(*arguments.trace, arguments.traceCloth, world);
      trace << "time,x,y,z\n";
      appendTraceRow(trace, world, *target);
    }

    // Where cloth passes through cloth (sim/intersections.hpp), at step 0, every K steps and the last.
    std::ostringstream intersections;
    std::size_t worstPairs = 0, lastPairs = 0;
    std::int64_t worstStep = 0;
    double countingSeconds = 0.0;  // kept out of the run's time: counting is not simulating
    const auto recordIntersections = [&] {
      const auto from = std::chrono::steady_clock::now();
      const sim::IntersectionCount count = sim::countIntersections(world);
      countingSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
      intersections << world.stepCount() << ',' << world.time() << ',' << count.pairs << ',' << count.skipped << '\n';
      lastPairs = count.pairs;
      if (count.pairs > worstPairs) {
        worstPairs = count.pairs;
        worstStep = world.stepCount();
      }
    };
    if (arguments.intersectionsEvery) {
      intersections << "step,time,pairs,skipped\n";
      recordIntersections();
    }

    const auto start = std::chrono::steady_clock::now();
    for (std::int64_t i = 0; i < steps; ++i) {
      if (playback.step() == sim::StepStatus::diverged) {
        playback.printReports();
        return reportDivergence(scene, world);
      }
      if (target) appendTraceRow(trace, world, *target);
      if (arguments.intersectionsEvery && ((i + 1) % *arguments.intersectionsEvery == 0 || i + 1 == steps)) {
        recordIntersections();
      }
    }
    playback.printReports();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - countingSeconds;

    std::vector<scene::OutputFile> files;
    for (const std::string& file : arguments.outputs) {
      const OutputKind kind = outputKind(file);
      files.push_back(
          {file,
           kind == OutputKind::mesh ? scene::objText(world)
           : kind == OutputKind::snapshot
               ? scene::snapshotDocument(scene, world).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
                     "\n"
               : scene::stateDocument(scene, world).dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
                     "\n"});
    }
    if (arguments.traceOut) files.push_back({*arguments.traceOut, trace.str()});
    if (arguments.intersectionsOut) files.push_back({*arguments.intersectionsOut, intersections.str()});
    scene::writeFilesAtomically(files);

    if (!arguments.quiet) {
      const sim::StrainStats strain = sim::structuralStrain(world);
      const sim::Energy energy = sim::energy(world);
      std::printf(
          "%s: %s in %.3f s; %zu cloth(s), %zu particles, %u piece(s); structural strain "
          "max %.2f %%, mean %.3f %%; energy %.4g J\n",
          scene.name.c_str(), playback.stepsRun().c_str(), seconds, world.cloths().size(), countParticles(world),
          countPieces(world), 100.0 * strain.max, 100.0 * strain.mean, energy.total());
      if (arguments.intersectionsEvery) {
        std::printf("intersecting triangle pairs: %zu at the end, at most %zu (step %lld)\n", lastPairs, worstPairs,
                    static_cast<long long>(worstStep));
      }
      for (const scene::OutputFile& file : files) std::printf("wrote %s\n", file.path.c_str());
    }
    return kExitOk;
  } catch (const scene::InputError& error) {
    return badInput(error.what());
  }
}

int listScenes() {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(scene::sceneDirectory(), error)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    try {
      const scene::Scene scene = scene::loadScene(file);
      std::printf("%-20s %s\n", file.stem().string().c_str(), scene.description.c_str());
    } catch (const scene::InputError& e) {
      std::printf("%-20s (invalid: %s)\n", file.stem().string().c_str(), e.what());
    }
  }
  return kExitOk;
}

}  // namespace drape::cli
