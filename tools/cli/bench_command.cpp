// drape-cli bench: the solver's speed on the standard scene hang2 (N x N, bench/hang2.hpp) and on
// more scenes, on one and more threads, against the naive baseline (bench/naive.hpp) in the same
// run; writes CSV, a gnuplot picture of time against particle count and a Markdown report.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "build_info.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "drape/bench/hang2.hpp"
#include "drape/bench/measure.hpp"
#include "drape/scene/error.hpp"
#include "drape/scene/output.hpp"
#include "drape/sim/world.hpp"
#include "touch_bench.hpp"

namespace drape::cli {

namespace {

constexpr double kStrainTarget = 0.05;  // what real fabric stretches: a few percent
constexpr int kSubstepChoices[] = {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48};

struct Row {
  std::string scene;
  int n = 0;  // hang2's N, 0 for other scenes
  bench::Measurement m;
};

// One sweep of Drape's hang2 solver tried in the search: substeps, and the worst strain after any
// frame.
struct Trial {
  int substeps;
  double worst;
};

// "2 x 1": substeps x sweeps.
std::string sweeps(const Row& row) { return std::to_string(row.m.substeps) + " x " + std::to_string(row.m.iterations); }

std::string cpuName() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown CPU";
}

// One block per series (Drape on T threads, the baseline at K sweeps): particles, ms per frame.
std::string plotData(const std::vector<Row>& rows, const std::vector<int>& threads, const std::vector<int>& sweeps) {
  std::ostringstream data;
  const auto block = [&](const char* solver, int key) {
    data << "# " << solver << ' ' << key << "\n";
    for (const Row& row : rows) {
      if (row.n == 0 || row.m.solver != solver) continue;
      if ((row.m.solver == "drape" ? row.m.threads : row.m.iterations) != key) continue;
      data << row.m.particles << ' ' << row.m.msPerFrame << "\n";
    }
    data << "\n\n";
  };
  for (int t : threads) block("drape", t);
  for (int k : sweeps) block("naive", k);
  return data.str();
}

// Run in the output folder (drawWithGnuplot): names its files relative to it.
std::string plotScript(const std::vector<int>& threads, const std::vector<int>& sweeps) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,600 font ',11'\n"
     << "if (!exists('outfile')) outfile = 'performance.png'\nset output outfile\n"
     << "set logscale xy\nset grid\nset key top left\n"
     << "set xlabel 'particles (hang2, N x N)'\nset ylabel 'ms per simulated frame (1/60 s)'\n"
     << "set title 'hang2: wall time per frame against particle count'\n"
     << "plot ";
  const std::string data = "'performance.dat'";
  int index = 0;
  for (int t : threads) {
    gp << (index ? ", " : "") << data << " index " << index << " with linespoints lw 2 pt 7 title 'Drape, " << t
       << (t == 1 ? " thread'" : " threads'");
    ++index;
  }
  for (int k : sweeps) {
    gp << (index ? ", " : "") << data << " index " << index << " with linespoints dt 2 pt 5 title 'naive Gauss-Seidel, "
       << k << " sweeps'";
    ++index;
  }
  gp << ", 2.5e-4*x with lines dt 3 lc 'gray' title 'linear in particles'\n";
  return gp.str();
}

}  // namespace

int bench(const BenchArguments& input) {
  try {
    BenchArguments arguments = input;
    std::erase(arguments.naiveIterations, 0);  // 0: no baseline
    std::erase(arguments.touchSizes, 0);       // 0: no touch cases
    // Smallest first, each once: the report compares the first size with the last.
    for (std::vector<int>* list :
         {&arguments.sizes, &arguments.threads, &arguments.naiveIterations, &arguments.touchSizes}) {
      std::sort(list->begin(), list->end());
      list->erase(std::unique(list->begin(), list->end()), list->end());
    }
    for (int n : arguments.sizes) {
      if (n < 2 || n > 1024) throw scene::InputError("--sizes: " + std::to_string(n) + " is not between 2 and 1024");
    }
    for (int n : arguments.touchSizes) {
      if (n < 2) throw scene::InputError("--touch-sizes: " + std::to_string(n) + " is not 0 or between 2 and 1024");
    }
    std::vector<TouchCase> cases;
    for (const TouchCase& c : touchCases()) {
      if (arguments.touchCases.empty() || std::ranges::count(arguments.touchCases, c.name)) cases.push_back(c);
    }
    for (const std::string& name : arguments.touchCases) {
      if (std::ranges::none_of(cases, [&](const TouchCase& c) { return c.name == name; }))
        throw scene::InputError("--touch-cases: no case is called \"" + name + "\"");
    }
    // Every scene is read before anything runs: a bad name fails at once.
    std::vector<scene::Scene> scenes;
    for (const std::string& name : arguments.scenes) {
      if (!name.empty()) scenes.push_back(loadScene(SceneArguments{name, {}}));  // --scenes "" runs none
    }
    const std::filesystem::path directory = arguments.outDir;

    std::vector<Row> rows;
    const auto progress = [&](const Row& row) {
      if (arguments.quiet) return;
      const bench::Measurement& m = row.m;
      std::printf("%-13s %7zu particles  %-5s %2d thread(s) %-12s %9.3f ms/frame  strain max %7.2f %% (run %7.2f %%)\n",
                  (row.n > 0 ? row.scene + " " + std::to_string(row.n) : row.scene).c_str(), m.particles,
                  m.solver.c_str(), m.threads, sweeps(row).c_str(), m.msPerFrame, 100.0 * m.strainMaxEnd,
                  100.0 * m.strainMaxRun);
      std::fflush(stdout);
    };
    std::vector<std::pair<int, std::vector<Trial>>> searches;  // N: the sweeps tried
    for (int n : arguments.sizes) {
      bench::Hang2Solver solver;
      solver.maxStretch = arguments.maxStretch;
      if (arguments.substeps > 0) {
        solver.substeps = arguments.substeps;
      } else {
        // The cheapest sweep that keeps every structural edge within 5 % at every frame.
        std::vector<Trial> tried;
        for (int substeps : kSubstepChoices) {
          solver.substeps = substeps;
          const bench::Measurement probe = bench::measureWorld(bench::hang2(n, solver), arguments.frames, 1, 1);
          tried.push_back({substeps, probe.diverged ? INFINITY : probe.strainMaxRun});
          if (!arguments.quiet) {
            std::printf("hang2 %d: %d substeps: worst strain %.2f %%\n", n, substeps, 100.0 * tried.back().worst);
            std::fflush(stdout);
          }
          if (tried.back().worst <= kStrainTarget) break;
        }
        searches.emplace_back(n, tried);
      }
      const sim::WorldSettings world = bench::hang2(n, solver);
      for (int t : arguments.threads) {
        rows.push_back({"hang2", n, bench::measureWorld(world, arguments.frames, t, arguments.repeats)});
        progress(rows.back());
      }
      for (int it : arguments.naiveIterations) {
        rows.push_back({"hang2", n, bench::measureNaive(world, arguments.frames, it, arguments.repeats)});
        progress(rows.back());
      }
    }
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      for (int t : arguments.threads) {
        rows.push_back(
            {scenes[k].name, 0, bench::measureWorld(scenes[k].world, arguments.frames, t, arguments.repeats)});
        progress(rows.back());
      }
    }
    // The scenes people touch, smallest first: one run each (touch_bench.hpp).
    std::vector<TouchRow> touched;
    std::vector<TouchSpread> spreads;
    for (int n : arguments.touchSizes) {
      for (const TouchCase& c : cases) {
        for (int t : arguments.threads) {
          touched.push_back(playTouchCase(c, n, t, arguments.touchBudget));
          if (!arguments.quiet) {
            std::printf("%s\n", touchLine(touched.back()).c_str());
            std::fflush(stdout);
          }
        }
        // The spread over chance, of the run on the most threads (every thread count ends the same),
        // where it played whole.
        const TouchRow& timed = touched.back();
        if (arguments.touchSpread > 0 && !timed.diverged && timed.framesRun == timed.frames) {
          spreads.push_back(spreadTouchCase(c, timed, arguments.touchSpread, timed.threads, arguments.touchBudget));
          if (!arguments.quiet) {
            std::printf("%-13s %4d x %-4d spread over %zu runs\n", c.name.c_str(), n, n,
                        spreads.back().freeStrainWorst.size());
            std::fflush(stdout);
          }
        }
      }
    }

    std::ostringstream csv;
    csv << "scene,n,particles,solver,threads,substeps,iterations,ms_per_frame,ms_per_frame_min,projections_per_s,"
           "strain_max_end,strain_mean_end,strain_max_run,diverged,bytes,bytes_per_particle,"
           "extra_line_steps_per_frame\n";
    for (const Row& row : rows) {
      const bench::Measurement& m = row.m;
      csv << row.scene << ',' << row.n << ',' << m.particles << ',' << m.solver << ',' << m.threads << ',' << m.substeps
          << ',' << m.iterations << ',' << m.msPerFrame << ',' << m.msPerFrameMin << ',' << m.projectionsPerSecond
          << ',' << m.strainMaxEnd << ',' << m.strainMeanEnd << ',' << m.strainMaxRun << ',' << (m.diverged ? 1 : 0)
          << ',' << m.bytes << ','
          << static_cast<double>(m.bytes) / static_cast<double>(std::max<std::size_t>(m.particles, 1)) << ','
          << m.extraLineSteps << '\n';
    }

    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double peakMiB = static_cast<double>(usage.ru_maxrss) / 1024.0;

    // hang2's target for the line solve (the scene file's, or --max-stretch).
    bench::Hang2Solver asked;
    asked.maxStretch = arguments.maxStretch;
    const double maxStretch = bench::hang2(2, asked).solver.maxStretch;
    std::ostringstream report;
    const bool native = std::string(kBuildDescription).find("native:") != std::string::npos;
    report << "# Performance" << (native ? " (a build for this CPU)" : "") << "\n\n"
           << "Generated by `tools/bench" << (native ? " --native" : "") << "` (`drape-cli bench --report "
           << arguments.report.value_or("") << " --out-dir " << arguments.outDir << "`); do not edit by hand.\n\n"
           << "Machine: " << cpuName() << ", " << std::thread::hardware_concurrency()
           << " hardware threads. Build: " << kBuildDescription << "; the full Newton line step solves "
           << sim::stiffSolveLanes() << " lines side by side"
           << (sim::stiffSolveLanes() == 8 ? " (AVX: this CPU has it, and the one file built for it is chosen at run "
                                             "time, in every build)"
                                           : " (SSE)")
           << ". " << arguments.frames << " frames of 1/60 s per run, the median of up to " << arguments.repeats
           << " timed runs (wall time of the steps alone), and beside it the fastest: runs vary from one to the "
              "next (on a shared virtual machine by up to a third), so the two can differ. The targets below are "
              "judged on the median, except linear growth, which is judged on the fastest runs.\n\n"
           << "## hang2\n\n"
           << "An N x N sheet, 1 m square in the x-z plane, 1 kg, pinned at two corners, structural + shear + bend "
              "(all rigid), gravity, dt = 1/60 s: it falls and swings from its two corners. Drape solves it with "
              "tethers to the pins and each row and column of stretch constraints solved at once "
              "(`\"stretchSolver\": \"lines\"`), in substeps of one sweep (how many for each N is below)"
           << (maxStretch > 0.0
                   ? ", working to `\"maxStretch\": " + format("%g", maxStretch) +
                         "`: the sweep's two Newton steps take the links' geometric stiffness where a line is taut, "
                         "the tethers are projected again after each, and where an edge is still more than " +
                         percent(maxStretch) + " long after them the sweep takes up to " +
                         std::to_string(sim::kExtraLineSteps) + " more steps; \"extra steps\" counts them per frame. "
                   : std::string(
                         ", with no stretch target (`--max-stretch 0`): plain Newton steps and no extra ones. "))
           << "The naive "
              "baseline is the textbook loop: an array of particle structs, "
              "Verlet, then Gauss-Seidel sweeps over every constraint in lattice order (`engine/bench/src/naive.cpp`). "
              "Strain is the structural constraints' |x_b - x_a| / r - 1: max and mean at the end, and the worst "
              "after any frame.\n\n"
           << "| N | particles | solver | threads | substeps x sweeps | extra steps | ms / frame | fastest run | "
              "projections / s | strain max (end) | mean (end) | worst (any frame) | bytes / particle |\n"
           << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& row : rows) {
      if (row.n == 0) continue;
      const bench::Measurement& m = row.m;
      report << "| " << row.n << " | " << m.particles << " | " << m.solver << " | " << m.threads << " | " << sweeps(row)
             << " | " << (m.solver == "drape" ? format("%.3f", m.extraLineSteps) : "") << " | "
             << format("%.3f", m.msPerFrame) << " | " << format("%.3f", m.msPerFrameMin) << " | "
             << format("%.3g", m.projectionsPerSecond) << " | " << (m.diverged ? "diverged" : percent(m.strainMaxEnd))
             << " | " << percent(m.strainMeanEnd) << " | " << percent(m.strainMaxRun) << " | "
             << format("%.0f", static_cast<double>(m.bytes) / static_cast<double>(m.particles)) << " |\n";
    }
    if (!searches.empty()) {
      report << "\nDrape's sweep for each N is the cheapest that keeps every structural edge within "
             << percent(kStrainTarget) << " of its rest length after every frame: for each number of substeps (of ";
      for (std::size_t i = 0; i < std::size(kSubstepChoices); ++i) report << (i ? ", " : "") << kSubstepChoices[i];
      report << "), one sweep each; the runs tried:\n\n";
      for (const auto& [n, tried] : searches) {
        report << "- N = " << n << ":";
        for (const Trial& trial : tried) {
          report << " " << trial.substeps << " substeps, worst " << percent(trial.worst) << ";";
        }
        if (!tried.empty() && !(tried.back().worst <= kStrainTarget)) report << " none held: the last one is timed;";
        report << "\n";
      }
    }
    // The targets, as measured here.
    const auto find = [&](int n, const char* solver, int threads) -> const Row* {
      for (const Row& row : rows) {
        if (row.n == n && row.m.solver == solver && (std::string(solver) != "drape" || row.m.threads == threads))
          return &row;
      }
      return nullptr;
    };
    report << "\n### Against the targets\n\n| target | measured | met |\n|---|---|---|\n";
    const auto target = [&](const std::string& what, const std::string& measured, bool met) {
      report << "| " << what << " | " << measured << " | " << (met ? "yes" : "**no**") << " |\n";
    };
    if (const Row* r = find(128, "drape", 1)) {
      target("hang2 128, strain <= 5 % at the end, no blow-up: <= 4 ms per frame on one core",
             format("%.2f ms", r->m.msPerFrame) + ", strain " + percent(r->m.strainMaxEnd) + " (worst " +
                 percent(r->m.strainMaxRun) + ")",
             r->m.msPerFrame <= 4.0 && r->m.strainMaxEnd <= kStrainTarget && !r->m.diverged);
    }
    if (const Row* r = find(256, "drape", 2)) {
      target("hang2 256 at <= 5 % strain: <= 8 ms per frame on 2 threads",
             format("%.2f ms", r->m.msPerFrame) + ", strain " + percent(r->m.strainMaxEnd),
             r->m.msPerFrame <= 8.0 && r->m.strainMaxEnd <= kStrainTarget && !r->m.diverged);
    }
    // Judged on the first thread count (one, by default): each more thread keeps its own working
    // rows for the line solves, as long as the longest line (so a share that shrinks as N grows),
    // which the other counts' figures show.
    const auto bytesPerParticle = [](const Row& r) {
      return static_cast<double>(r.m.bytes) / static_cast<double>(r.m.particles);
    };
    for (int n : arguments.sizes) {
      const int threads = arguments.threads.front();
      const Row* r = find(n, "drape", threads);
      if (!r) continue;
      std::string measured = format("%.0f bytes", bytesPerParticle(*r));
      for (std::size_t t = 1; t < arguments.threads.size(); ++t) {
        if (const Row* other = find(n, "drape", arguments.threads[t])) {
          measured += " (" + std::to_string(arguments.threads[t]) +
                      " threads: " + format("%.0f", bytesPerParticle(*other)) + ")";
        }
      }
      target("hang2 " + std::to_string(n) + ": <= 200 bytes per particle, constraints included, on " +
                 (threads == 1 ? std::string("one thread") : std::to_string(threads) + " threads"),
             measured, bytesPerParticle(*r) <= 200.0);
    }
    if (arguments.sizes.size() >= 2) {
      const Row* small = find(arguments.sizes.front(), "drape", 1);
      const Row* large = find(arguments.sizes.back(), "drape", 1);
      if (small && large) {
        // On the fastest runs: a ratio of two medians moves with every slow run of the small, quick case.
        const double growth = (large->m.msPerFrameMin / small->m.msPerFrameMin) /
                              (static_cast<double>(large->m.particles) / static_cast<double>(small->m.particles));
        target("cost grows linearly with particles (time per particle on the fastest run, largest over smallest N)",
               format("%.2fx", growth) + " (substeps x sweeps " + sweeps(*small) + " -> " + sweeps(*large) + ")",
               growth <= 1.5);
      }
    }
    bool same = true;
    for (const Row& a : rows) {
      for (const Row& b : rows) {
        if (a.n > 0 && a.n == b.n && a.m.solver == "drape" && b.m.solver == "drape") {
          same = same && a.m.strainMaxEnd == b.m.strainMaxEnd && a.m.strainMeanEnd == b.m.strainMeanEnd &&
                 a.m.strainMaxRun == b.m.strainMaxRun;
        }
      }
    }
    if (arguments.threads.size() < 2) same = false;  // nothing was compared
    target("1 and N threads give the same result bit for bit",
           std::string(arguments.threads.size() < 2 ? "one thread count only: not compared here"
                       : same                       ? "the same strains, to the last bit, at every thread count above"
                                                    : "strains differ between thread counts") +
               "; sim_tests FastSweep.* compare every position (1, 2, 3, 5 threads, with tearing and XPBD)",
           same);
    report << "\nThe ratio to the naive baseline (>= 50x at equal strain) is in the next section.\n";
    // The picture, as the report's own folder sees it.
    std::filesystem::path picture =
        std::filesystem::absolute(std::filesystem::path(arguments.outDir) / "performance.png");
    if (arguments.report) {
      picture = picture.lexically_relative(std::filesystem::absolute(*arguments.report).parent_path());
    }
    report << "\n![time per frame against particle count](" << picture.generic_string() << ")\n\n"
           << "## Against the naive baseline\n\n"
           << "At equal strain: the cheapest naive run that ends with no more strain than Drape on one thread, "
              "divided by Drape's time. Where no naive run gets there, the costliest one is used and the ratio is a "
              "lower bound (more sweeps cost more and strain less).\n\n"
           << "| N | Drape, 1 thread | naive run compared | ratio |\n|---|---|---|---|\n";
    for (int n : arguments.sizes) {
      const Row* drape = nullptr;
      std::vector<const Row*> naive;
      for (const Row& row : rows) {
        if (row.n != n) continue;
        if (row.m.solver == "drape" && row.m.threads == 1) drape = &row;
        if (row.m.solver == "naive") naive.push_back(&row);
      }
      std::erase_if(naive, [](const Row* r) { return r->m.diverged; });
      if (!drape || drape->m.diverged || naive.empty()) continue;
      const Row* match = nullptr;
      for (const Row* candidate : naive) {
        const bool reaches = candidate->m.strainMaxEnd <= drape->m.strainMaxEnd;
        if (reaches && (!match || candidate->m.msPerFrame < match->m.msPerFrame)) match = candidate;
      }
      const bool bound = match == nullptr;
      if (bound) {
        match = *std::max_element(naive.begin(), naive.end(),
                                  [](const Row* a, const Row* b) { return a->m.msPerFrame < b->m.msPerFrame; });
      }
      report << "| " << n << " | " << format("%.3f ms", drape->m.msPerFrame) << ", strain "
             << percent(drape->m.strainMaxEnd) << " | " << match->m.iterations
             << " sweeps: " << format("%.3f ms", match->m.msPerFrame) << ", strain "
             << (match->m.diverged ? "diverged" : percent(match->m.strainMaxEnd)) << " | " << (bound ? "≥ " : "")
             << format("%.0fx", match->m.msPerFrame / drape->m.msPerFrame) << " |\n";
    }
    report << "\n## Where the time goes\n\n"
           << "Milliseconds per frame in each stage of the pipeline, and in brackets each part of a stage that "
              "does several jobs, its own time (a part run inside another is not counted twice); a stage a scene "
              "does not need is not in its pipeline at all. `(step)` is the whole step: what it has beyond the "
              "stages is the pipeline's own cost.\n\n";
    for (const Row& row : rows) {
      const bool lastHang2 = row.n == arguments.sizes.back() && row.m.solver == "drape";
      if (!(row.n == 0 || lastHang2)) continue;
      report << "- " << (row.n > 0 ? "hang2 " + std::to_string(row.n) : row.scene) << ", " << row.m.threads
             << (row.m.threads == 1 ? " thread" : " threads") << " (" << row.m.particles << " particles, strain max "
             << percent(row.m.strainMaxEnd) << ", "
             << format("%.0f", static_cast<double>(row.m.bytes) / static_cast<double>(row.m.particles))
             << " bytes/particle):";
      double stages = 0.0, step = 0.0;
      for (const bench::StageMs& stage : row.m.stageMs) (stage.stage == "(step)" ? step : stages) += stage.ms;
      report << " " << bench::describe(row.m.stageMs);
      report << " outside the stages " << format("%.3f", step - stages) << " ms ("
             << format("%.1f", step > 0.0 ? 100.0 * (step - stages) / step : 0.0) << " %)\n";
    }
    for (const Row& row : rows) {
      if (!(row.n == arguments.sizes.back() && row.m.solver == "drape" && row.m.threads == arguments.threads.front())) {
        continue;
      }
      report << "\nBytes per particle of hang2 " << row.n << ", by what they are for:";
      for (const auto& [what, count] : row.m.bytesBy) {
        report << " " << what << " "
               << format("%.1f", static_cast<double>(count) / static_cast<double>(row.m.particles)) << ";";
      }
      report << " total " << format("%.1f", static_cast<double>(row.m.bytes) / static_cast<double>(row.m.particles))
             << ".\n";
    }
    if (!touched.empty()) report << "\n" << touchSection(touched, arguments.touchBudget, spreads);
    report << "\nPeak resident memory of the whole benchmark process: " << format("%.0f", peakMiB) << " MiB.\n";

    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) throw scene::InputError(directory.string() + ": cannot create the folder: " + error.message());
    scene::writeFilesAtomically(
        {{directory / "performance.csv", csv.str()},
         {directory / "performance.dat", plotData(rows, arguments.threads, arguments.naiveIterations)},
         {directory / "performance.gp", plotScript(arguments.threads, arguments.naiveIterations)},
         {directory / "touch.csv", touchCsv(touched)},
         {directory / "touch-spread.csv", touchSpreadCsv(spreads)}});
    drawWithGnuplot(directory, "performance.gp", "performance.png");
    if (arguments.report) scene::writeFileAtomically(*arguments.report, report.str());
    if (!arguments.quiet) {
      std::printf("wrote %s/performance.csv, performance.png%s%s\n", directory.c_str(), arguments.report ? " and " : "",
                  arguments.report ? arguments.report->c_str() : "");
    }
    return kExitOk;
  } catch (const scene::InputError& error) {
    return badInput(error.what());
  }
}

}  // namespace drape::cli
