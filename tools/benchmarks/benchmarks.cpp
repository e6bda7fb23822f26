// drape-benchmarks: the same cases as drape-cli bench under Google Benchmark (Debian's
// libbenchmark-dev), for its statistics, filters and JSON output:
//   build/release/tools/benchmarks/drape-benchmarks --benchmark_filter=Hang2
// Each iteration is a whole run of hang2 (120 frames from the flat start: the fall, the whip and the
// swing cost differently); counters give simulated frames per second of wall time (hang2) or of
// CPU time (the single-threaded baseline) and the strain reached, in percent.
#include <benchmark/benchmark.h>

#include "drape/bench/hang2.hpp"
#include "drape/bench/naive.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace {

using namespace drape;

constexpr int kFrames = 120;

// The cheapest sweep that keeps hang2 within 5 % strain at every frame (drape-cli bench finds it;
// see docs/performance.md): one substep with the tethers after each line step, and up to two
// more line steps where an edge is still over 4 %, at every N.
bench::Hang2Solver solverFor(int) {
  bench::Hang2Solver solver;
  solver.substeps = 1;
  solver.tethersBetweenSteps = true;
  return solver;
}

void Hang2(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const sim::WorldSettings settings = bench::hang2(n, solverFor(n));
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

BENCHMARK(Hang2)
    ->ArgNames({"N", "threads"})
    ->ArgsProduct({{16, 64, 128, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(Naive)->ArgNames({"N", "sweeps"})->ArgsProduct({{16, 64, 128}, {10}})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
