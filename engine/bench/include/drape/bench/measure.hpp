// Measuring a solver on a scene: wall time per simulated frame, constraint projections per
// second, the strain it reaches, the bytes it keeps.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "drape/sim/pipeline.hpp"
#include "drape/sim/settings.hpp"

namespace drape::bench {

// Wall time per frame in one stage of the pipeline, and in each of its parts (their own time, in
// the order they first ran; sim::StageTiming::parts).
struct StageMs {
  std::string stage;
  double ms = 0.0;
  std::vector<std::pair<std::string, double>> parts;
};

// A world's profile as ms per frame, over `frames` frames.
std::vector<StageMs> stageMs(const sim::Profile& profile, int frames);

// "stage 1.234; stage 0.500 (part 0.200, part 0.100); ...": each stage with its ms per frame and
// its parts' (%.3f).
std::string describe(const std::vector<StageMs>& stages);

struct Measurement {
  std::string solver;  // "drape" or "naive"
  int threads = 1;
  int substeps = 1;
  int iterations = 1;
  std::size_t particles = 0;
  std::size_t constraints = 0;  // stretch + shear + bend
  std::size_t tethers = 0;
  int frames = 0;
  double msPerFrame = 0.0;  // wall time, median over the repeats
  double msPerFrameMin = 0.0;
  double projectionsPerSecond = 0.0;  // constraints (and tethers) projected per second of wall time
  double strainMaxEnd = 0.0;          // structural strain after the last frame
  double strainMeanEnd = 0.0;
  double strainMaxRun = 0.0;    // worst structural strain after any frame
  bool diverged = false;        // non-finite (naive) or stopped by the guard (drape)
  double extraLineSteps = 0.0;  // drape: line steps a frame took beyond its sweeps' two (solver.maxStretch)
  std::size_t bytes = 0;        // what the solver keeps for the cloth: state, rest data, constraints, scratch
  std::vector<std::pair<std::string, std::size_t>> bytesBy;  // drape: the same by what it is for
  // drape: ms per frame in each pipeline stage, then "(step)": the whole step, stages and the rest
  std::vector<StageMs> stageMs;
};

// Drape's world. Every run times its steps alone; the first also takes the strain after each
// frame (the trajectory is the same bit for bit in every run). Up to `repeats` runs, fewer once the
// case has taken 20 s.
Measurement measureWorld(const sim::WorldSettings& world, int frames, int threads, int repeats);

// The naive baseline (naive.hpp) on the world's first cloth.
Measurement measureNaive(const sim::WorldSettings& world, int frames, int iterations, int repeats);

// The middle value, or the mean of the two middle ones; NaN for none.
double median(std::vector<double> values);

}  // namespace drape::bench
