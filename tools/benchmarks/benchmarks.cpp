// drape-benchmarks: the same cases as drape-cli bench under Google Benchmark (Debian's
// libbenchmark-dev), for its statistics, filters and JSON output:
//   build/release/tools/benchmarks/drape-benchmarks --benchmark_filter=Hang2
// Each iteration is a whole run of hang2 (120 frames from the flat start: the fall, the whip and the
// swing cost differently); counters give simulated frames per second of wall time (hang2) or of
// CPU time (the single-threaded baseline) and the strain reached, in percent. Draw times the
// renderer (Mesa's llvmpipe through OSMesa, as drape-cli render) on a scene as the app first shows
// it: 1280 x 800, the app's picture options, with or without FXAA.
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <cmath>
#include <memory>
#include <string>

#include "context.hpp"

#include "drape/bench/hang2.hpp"
#include "drape/bench/naive.hpp"
#include "drape/render/camera.hpp"
#include "drape/render/renderer.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace {

using namespace drape;

constexpr int kFrames = 120;

void Hang2(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  // As the scene file solves it: one substep with the tethers after each line step, and up to four
  // more line steps where an edge is still over 4 % (the cheapest sweep within 5 % at every frame
  // that drape-cli bench finds at every N: docs/performance.md).
  const sim::WorldSettings settings = bench::hang2(n);
  double strain = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    sim::World world(settings);
    world.setThreads(threads);
    state.ResumeTiming();
    world.run(kFrames);
    state.PauseTiming();
    strain = sim::structuralStrain(world).max;
    state.ResumeTiming();
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kFrames, benchmark::Counter::kIsRate);
  state.counters["strain_max_percent"] = 100.0 * strain;
  state.counters["particles"] = static_cast<double>(n) * n;
}

void Naive(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  const sim::WorldSettings settings = bench::hang2(n);
  double strain = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    bench::NaiveCloth cloth(settings, iterations);
    state.ResumeTiming();
    for (int frame = 0; frame < kFrames; ++frame) cloth.step();
    state.PauseTiming();
    strain = cloth.strainMax();
    state.ResumeTiming();
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kFrames, benchmark::Counter::kIsRate);
  state.counters["strain_max_percent"] = 100.0 * strain;
  state.counters["particles"] = static_cast<double>(n) * n;
}

// The scenes Draw times: as shipped, after a second of simulation (a settled desk, a cloth draped
// over its sphere).
const char* const kDrawScenes[] = {"desk", "drape-sphere", "hang"};

void Draw(benchmark::State& state) {
  const char* name = kDrawScenes[state.range(0)];
  constexpr int kWidth = 1280, kHeight = 800;
  const std::unique_ptr<cli::OffscreenContext> context = cli::OffscreenContext::create(kWidth, kHeight);
  render::Renderer renderer(context->procAddress());
  sim::World world(scene::loadScene(scene::resolveScenePath(name)).world);
  world.run(static_cast<int>(std::lround(1.0 / world.settings().solver.dt)));
  // The app's first view: from the front right and a little above, framed in the 72 % of the
  // window its panel leaves, and its picture options (app/panels.hpp).
  constexpr double kUncovered = 0.72, kAspect = static_cast<double>(kWidth) / kHeight;
  glm::dvec3 lower, upper;
  render::sceneBounds(world, lower, upper);
  render::Camera camera = render::Camera::framing(lower, upper, 0.6, 0.45, kAspect * kUncovered);
  camera.pan(std::tan(camera.fieldOfView / 2.0) * kAspect * (1.0 - kUncovered), 0.0);
  render::FrameOptions options;
  options.multisample = false;
  options.fxaa = state.range(1) != 0;
  options.shadowSoftness = 0;
  options.shadowMapSize = 1024;
  renderer.render(world, camera, kWidth, kHeight, options);  // shaders compiled, buffers made
  renderer.finish();
  // The CPU time of every thread (llvmpipe draws on its own): steadier than the wall time on a
  // shared machine.
  const auto processSeconds = [] {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  };
  const double cpuBefore = processSeconds();
  for (auto _ : state) {
    renderer.render(world, camera, kWidth, kHeight, options);
    renderer.finish();
  }
  state.counters["cpu_ms"] = 1e3 * (processSeconds() - cpuBefore) / static_cast<double>(state.iterations());
  state.SetLabel(name);
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK(Draw)
    ->ArgNames({"scene", "fxaa"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(Hang2)
    ->ArgNames({"N", "threads"})
    ->ArgsProduct({{16, 64, 128, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(Naive)->ArgNames({"N", "sweeps"})->ArgsProduct({{16, 64, 128}, {10}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
