#include "drape/bench/measure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "drape/bench/naive.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kBudgetSeconds = 20.0;  // no further repeats once a case has taken this long

void timing(Measurement& m, const std::vector<double>& seconds, double projectionsPerFrame) {
  const double perFrame = median(seconds) / m.frames;
  m.msPerFrame = 1e3 * perFrame;
  m.msPerFrameMin = 1e3 * *std::min_element(seconds.begin(), seconds.end()) / m.frames;
  m.projectionsPerSecond = perFrame > 0.0 ? projectionsPerFrame / perFrame : 0.0;
}

}  // namespace

std::vector<StageMs> stageMs(const sim::Profile& profile, int frames) {
  const double perFrame = 1e3 / std::max(frames, 1);
  std::vector<StageMs> stages;
  for (const sim::StageTiming& t : profile) {
    StageMs stage{std::string(sim::name(t.stage)), t.totalSeconds * perFrame, {}};
    for (const sim::StageTiming& part : t.parts) {
      stage.parts.emplace_back(std::string(sim::name(part.stage)), part.totalSeconds * perFrame);
    }
    stages.push_back(std::move(stage));
  }
  return stages;
}

std::string describe(const std::vector<StageMs>& stages) {
  std::string text;
  char number[32];
  for (const StageMs& stage : stages) {
    std::snprintf(number, sizeof number, "%.3f", stage.ms);
    text += (text.empty() ? "" : " ") + stage.stage + " " + number;
    for (std::size_t k = 0; k < stage.parts.size(); ++k) {
      std::snprintf(number, sizeof number, "%.3f", stage.parts[k].second);
      text += (k == 0 ? " (" : ", ") + stage.parts[k].first + " " + number;
    }
    text += stage.parts.empty() ? ";" : ");";
  }
  return text;
}

Measurement measureWorld(const sim::WorldSettings& settings, int frames, int threads, int repeats) {
  Measurement m;
  m.solver = "drape";
  m.threads = threads;
  m.substeps = settings.solver.substeps;
  m.iterations = settings.solver.iterations;
  m.frames = frames;
  std::vector<double> seconds;
  double spent = 0.0;
  for (int repeat = 0; repeat < std::max(repeats, 1) && (repeat == 0 || spent < kBudgetSeconds); ++repeat) {
    sim::World world(settings);
    world.setThreads(threads);
    m.substeps = world.substeps();  // more than asked for a fine fabric (sim::substepsFor)
    double stepping = 0.0;
    for (int frame = 0; frame < frames; ++frame) {
      const auto start = Clock::now();
      const sim::StepStatus status = world.step();
      stepping += std::chrono::duration<double>(Clock::now() - start).count();
      if (repeat > 0) continue;
      // The first run also watches the strain, outside the timed part.
      m.diverged = m.diverged || status == sim::StepStatus::diverged;
      m.strainMaxRun = std::max(m.strainMaxRun, sim::structuralStrain(world).max);
    }
    seconds.push_back(stepping);
    spent += stepping;
    if (repeat > 0) continue;
    const sim::StrainStats end = sim::structuralStrain(world);
    m.strainMaxEnd = end.max;
    m.strainMeanEnd = end.mean;
    m.extraLineSteps = static_cast<double>(world.extraLineSteps()) / frames;
    const sim::MemoryUse use = world.memoryUse();
    m.bytes = use.total();
    m.bytesBy = {{"state", use.state},
                 {"rest positions and triangles", use.rest},
                 {"constraints", use.constraints},
                 {"tethers", use.tethers},
                 {"lines", use.lines},
                 {"guard's copy", use.guard},
                 {"topology", use.topology},
                 {"scratch", use.solver}};
    for (const sim::Cloth& cloth : world.cloths()) {
      m.particles += cloth.state.position.size();
      for (sim::ConstraintKind kind : sim::kConstraintKinds) {
        if (cloth.settings.material(kind).stiffness > 0.0) m.constraints += cloth.rest.of(kind).size();
      }
    }
    m.tethers = world.tetherCount();
    m.stageMs = stageMs(world.profile(), frames);
    m.stageMs.push_back({"(step)", 1e3 * stepping / frames, {}});
  }
  timing(m, seconds, static_cast<double>(m.substeps) * m.iterations * static_cast<double>(m.constraints + m.tethers));
  return m;
}

Measurement measureNaive(const sim::WorldSettings& settings, int frames, int iterations, int repeats) {
  Measurement m;
  m.solver = "naive";
  m.iterations = iterations;
  m.frames = frames;
  std::vector<double> seconds;
  double spent = 0.0;
  for (int repeat = 0; repeat < std::max(repeats, 1) && (repeat == 0 || spent < kBudgetSeconds); ++repeat) {
    NaiveCloth cloth(settings, iterations);
    double stepping = 0.0;
    for (int frame = 0; frame < frames; ++frame) {
      const auto start = Clock::now();
      cloth.step();
      stepping += std::chrono::duration<double>(Clock::now() - start).count();
      if (repeat > 0) continue;
      m.diverged = m.diverged || !cloth.finite();
      if (!m.diverged) m.strainMaxRun = std::max(m.strainMaxRun, cloth.strainMax());
    }
    seconds.push_back(stepping);
    spent += stepping;
    if (repeat > 0) continue;
    m.strainMaxEnd = cloth.strainMax();
    m.strainMeanEnd = cloth.strainMean();
    m.particles = cloth.particleCount();
    m.constraints = cloth.constraintCount();
    m.bytes = cloth.memoryBytes();
  }
  timing(m, seconds, static_cast<double>(iterations) * static_cast<double>(m.constraints));
  return m;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  if (n == 0) return NAN;
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace drape::bench
