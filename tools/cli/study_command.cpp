// drape-cli study: error against run time. Sweeps configurations of a scene (every combination of
// the --sweep values whose keys go together: sim::conflict), and for each reports CPU time per simulated second (median
// of repeats), the constraint error (structural strain over the run) and the trajectory error (RMS distance from a
// reference run of the same scene at 8x the substeps and 4x the iterations); marks the Pareto front
// in a log-log gnuplot picture; and adds each integrator's observed convergence order on the
// harmonic oscillator against its exact solution.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "drape/analysis/analytic.hpp"
#include "drape/analysis/convergence.hpp"
#include "drape/bench/measure.hpp"
#include "drape/scene/error.hpp"
#include "drape/scene/gesture.hpp"
#include "drape/scene/output.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::cli {

namespace {

constexpr int kSampleEvery = 5;  // steps between trajectory samples

struct Sweep {
  std::string key;
  std::vector<std::string> values;
};

Sweep parseSweep(const std::string& text) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == text.size()) {
    throw scene::InputError("--sweep " + text + ": expected path=value1,value2,... e.g. solver.iterations=5,10,20");
  }
  Sweep sweep{text.substr(0, equals), {}};
  std::stringstream values(text.substr(equals + 1));
  std::string value;
  while (std::getline(values, value, ',')) sweep.values.push_back(value);
  return sweep;
}

struct Trajectory {
  std::vector<std::vector<sim::Vec3>> samples;  // every kSampleEvery steps, all particles of all cloths
  double cpuSecondsPerSimulatedSecond = 0.0;
  double strainMax = 0.0;   // over the whole run
  double strainMean = 0.0;  // mean over the run of the per-step mean |strain|
  bool diverged = false;
};

Trajectory simulate(const scene::Scene& scene, std::int64_t steps, const std::optional<std::string>& gesture) {
  Playback playback(scene, gesture);
  sim::World& world = playback.world();
  Trajectory t;
  const auto sample = [&] {
    std::vector<sim::Vec3> all;
    for (const sim::Cloth& cloth : world.cloths())
      all.insert(all.end(), cloth.state.position.begin(), cloth.state.position.end());
    t.samples.push_back(std::move(all));
  };
  sample();
  double stepping = 0.0, strainSum = 0.0;
  for (std::int64_t i = 1; i <= steps; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const sim::StepStatus status = playback.step();
    stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (status == sim::StepStatus::diverged) {
      t.diverged = true;
      return t;
    }
    const sim::StrainStats strain = sim::structuralStrain(world);
    t.strainMax = std::max(t.strainMax, strain.max);
    strainSum += strain.mean;
    if (i % kSampleEvery == 0) sample();
  }
  t.cpuSecondsPerSimulatedSecond = stepping / std::max(world.time(), 1e-12);
  t.strainMean = strainSum / static_cast<double>(std::max<std::int64_t>(steps, 1));
  return t;
}

double rmsDistance(const Trajectory& a, const Trajectory& b) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t s = 0; s < std::min(a.samples.size(), b.samples.size()); ++s) {
    // A tear or a drawn cloth can make the runs' particle counts differ: the common ones count.
    for (std::size_t i = 0; i < std::min(a.samples[s].size(), b.samples[s].size()); ++i) {
      const sim::Vec3 d = a.samples[s][i] - b.samples[s][i];
      sum += glm::dot(d, d);
      ++count;
    }
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) : NAN;
}

scene::Scene refined(scene::Scene scene, int substepFactor, int iterationFactor) {
  scene.world.solver.substeps *= substepFactor;
  // A fine fabric's substeps follow its spacing (sim::substepsFor): they are refined by as much.
  scene.world.solver.fabricSubstepSpeed *= substepFactor;
  scene.world.solver.iterations *= iterationFactor;
  return scene;
}

}  // namespace

int study(const StudyArguments& arguments) {
  try {
    namespace fs = std::filesystem;
    std::vector<Sweep> sweeps;
    for (const std::string& text : arguments.sweeps) sweeps.push_back(parseSweep(text));
    const scene::Scene base = loadScene(arguments.input);
    std::optional<interact::GestureScript> script;
    if (arguments.gesture) script = scene::loadGesture(*arguments.gesture);
    const std::int64_t steps = stepCount(base, arguments.steps, arguments.seconds, script ? &*script : nullptr);
    if (arguments.choose && !std::isfinite(*arguments.choose)) {
      throw scene::InputError("--choose: expected a finite strain such as 0.05");
    }
    if (base.world.solver.model != sim::Model::position && arguments.sweeps.empty()) {
      throw scene::InputError(base.source + ": study refines substeps and iterations; give --sweep values to compare");
    }
    const fs::path directory = outputFolder(arguments.outDir);

    // The reference: 8x the substeps and 4x the iterations; refining once more (16x, 8x) shows
    // how far the reference itself is from converged.
    Trajectory reference, finer;
    double referenceUncertainty = NAN;
    if (!arguments.noReference) {
      reference = simulate(refined(base, 8, 4), steps, arguments.gesture);
      finer = simulate(refined(base, 16, 8), steps, arguments.gesture);
      if (reference.diverged || finer.diverged) throw scene::InputError(base.source + ": the reference run diverged");
      referenceUncertainty = rmsDistance(reference, finer);
    }

    struct Row {
      std::string label;
      double time, strainMax, strainMean, error;
      bool diverged;
      bool pareto = false;
    };
    std::vector<Row> rows;
    // Combinations whose keys do not go together (sim::conflict: a max stretch with the seed's
    // sweep, say), not run: their labels and the first one's reason.
    std::vector<std::string> skipped;
    std::string skippedWhy;
    std::vector<std::size_t> index(sweeps.size(), 0);
    for (bool more = true; more;) {
      std::vector<std::string> overrides = arguments.input.overrides;
      std::string label;
      for (std::size_t s = 0; s < sweeps.size(); ++s) {
        overrides.push_back(sweeps[s].key + "=" + sweeps[s].values[index[s]]);
        label += (label.empty() ? "" : " ") + sweeps[s].key.substr(sweeps[s].key.rfind('.') + 1) + "=" +
                 sweeps[s].values[index[s]];
      }
      std::size_t next = 0;
      while (next < sweeps.size() && ++index[next] == sweeps[next].values.size()) index[next++] = 0;
      more = next < sweeps.size();
      std::optional<scene::Scene> loaded;
      try {
        loaded = scene::loadScene(scene::resolveScenePath(arguments.input.scene), overrides);
      } catch (const scene::KeyConflict& conflict) {
        // Only a combination the sweep made: the scene as given must load.
        if (sweeps.empty()) throw;
        if (skipped.empty()) {
          // Named as the report names the scene (from assets/ on, not where this machine keeps it).
          skippedWhy = conflict.what();
          const std::size_t assets = base.source.rfind("assets/");
          if (assets != std::string::npos && skippedWhy.rfind(base.source, 0) == 0)
            skippedWhy = base.source.substr(assets) + skippedWhy.substr(base.source.size());
        }
        skipped.push_back(label);
        continue;
      }
      const scene::Scene& configured = *loaded;
      std::vector<double> times;
      Trajectory run;
      for (int r = 0; r < arguments.repeats; ++r) {
        run = simulate(configured, steps, arguments.gesture);
        times.push_back(run.cpuSecondsPerSimulatedSecond);
      }
      // A run that diverged has no time or strain worth comparing.
      rows.push_back({label.empty() ? "scene as written" : label, run.diverged ? NAN : bench::median(times),
                      run.diverged ? NAN : run.strainMax, run.diverged ? NAN : run.strainMean,
                      run.diverged || arguments.noReference ? NAN : rmsDistance(run, reference), run.diverged});
    }
    if (rows.empty())
      throw scene::InputError("no combination of the sweeps has keys that go together; the first: " + skippedWhy);
    // Pareto front: no other run is both faster and more accurate.
    // Without a reference the accuracy compared is the worst strain.
    const auto inaccuracy = [&](const Row& row) { return arguments.noReference ? row.strainMax : row.error; };
    for (Row& row : rows) {
      row.pareto = !row.diverged && std::none_of(rows.begin(), rows.end(), [&](const Row& other) {
        return !other.diverged && &other != &row && other.time <= row.time && inaccuracy(other) <= inaccuracy(row) &&
               (other.time < row.time || inaccuracy(other) < inaccuracy(row));
      });
    }

    // With --choose: the cheapest run whose worst strain stays within the bound. Times within 10 %
    // of the cheapest count as equal (timing noise is about that), and among those the lower
    // strain wins, so that the choice does not flip from one study to the next.
    const Row* chosen = nullptr;
    if (arguments.choose) {
      const auto within = [&](const Row& row) { return !row.diverged && row.strainMax <= *arguments.choose; };
      double cheapest = INFINITY;
      for (const Row& row : rows) {
        if (within(row)) cheapest = std::min(cheapest, row.time);
      }
      for (const Row& row : rows) {
        if (within(row) && row.time <= 1.1 * cheapest && (!chosen || row.strainMax < chosen->strainMax)) chosen = &row;
      }
    }

    std::ostringstream csv, report, gp;
    csv << "config,cpu_s_per_simulated_s,strain_max,strain_mean,rms_error_m,pareto,chosen\n";
    for (const Row& r : rows) {
      csv << '"' << r.label << "\"," << r.time << ',' << r.strainMax << ',' << r.strainMean << ',' << r.error << ','
          << (r.pareto ? 1 : 0) << ',' << (&r == chosen ? 1 : 0) << '\n';
    }
    // Run in the output folder (drawWithGnuplot): its files are named relative to it.
    gp << "set terminal pngcairo size 900,600 font ',10'\n"
       << "if (!exists('outfile')) outfile = 'accuracy.png'\nset output outfile\nset datafile separator ','\nset "
          "logscale xy\nset key top right\n"
       << "set xlabel 'CPU time per simulated second (s)'\nset ylabel '"
       << (arguments.noReference ? "worst structural strain over the run" : "RMS distance from the reference (m)")
       << "'\n"
       << "set title '" << base.name << ": error against run time (Pareto front joined)'\n";
    const int y = arguments.noReference ? 3 : 5;
    gp << "plot 'accuracy.csv' skip 1 using 2:" << y
       << " with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'configurations', \\\n"
       << "     '' skip 1 using 2:($6 == 1 ? $" << y
       << " : 1/0) smooth unique with linespoints pt 7 ps 1.6 lw 2 lc rgb "
          "'#d62728' title 'Pareto front', \\\n"
       << "     '' skip 1 using 2:" << y << ":1 with labels offset 0,1 font ',7' notitle\n";

    report << "# Error against run time: " << base.name << "\n\n"
           << "Generated by `drape-cli study` (the command line is below); do not edit.\n\n"
           << "Each configuration runs " << steps << " steps of `" << base.source.substr(base.source.rfind("assets/"))
           << "`. *Time*: CPU seconds per simulated second, median of " << arguments.repeats
           << " runs, this machine, one thread. *Strain*: structural strain |x_b - x_a| / r - 1, the worst over\n"
           << "the whole run and the mean of the per-step mean. *Error*: RMS distance of all particles, sampled\n"
           << "every " << kSampleEvery
           << " steps, from a reference run at 8x the substeps and 4x the iterations of the "
           << "scene as written; refining the reference once more (16x, 8x) moves it by " << referenceUncertainty
           << " m RMS, the floor below which errors here mean nothing"
           << (arguments.noReference
                   ? " (here: no reference run, --no-reference; the front is over time and worst strain)"
                   : "")
           << ".\n\n";
    if (arguments.gesture) report << "Every run plays the gesture script `" << *arguments.gesture << "`.\n\n";
    if (arguments.choose) {
      char line[512];
      if (chosen) {
        std::snprintf(line, sizeof line,
                      "**Chosen** (the cheapest whose worst strain stays within %.2f %%; times within 10 %% count "
                      "as equal, then the lower strain wins): %s, %.4f s/s, worst strain %.2f %%.\n\n",
                      100.0 * *arguments.choose, chosen->label.c_str(), chosen->time, 100.0 * chosen->strainMax);
      } else {
        std::snprintf(line, sizeof line, "**Chosen**: none; no configuration kept the worst strain within %.2f %%.\n\n",
                      100.0 * *arguments.choose);
      }
      report << line;
    }
    // The picture, relative to where the report goes.
    fs::path picture = directory / "accuracy.png";
    if (arguments.report) {
      const fs::path from = fs::absolute(fs::path(*arguments.report)).parent_path();
      picture = fs::absolute(picture).lexically_relative(from);
    }
    report << "![error against run time](" << picture.string() << ")\n\n"
           << "| configuration | time (s/s) | worst strain | mean strain | error (m) | Pareto "
              "|\n|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %.4f | %.2f %% | %.3f %% | %s | %s |\n", r.label.c_str(), r.time,
                    100.0 * r.strainMax, 100.0 * r.strainMean,
                    r.diverged ? "diverged" : (std::to_string(r.error)).c_str(), r.pareto ? "yes" : "");
      report << line;
    }
    if (!skipped.empty()) {
      report << "\nNot run, their keys do not go together (`sim::conflict`; the first: " << skippedWhy << "): ";
      for (std::size_t k = 0; k < skipped.size(); ++k) report << (k > 0 ? ", " : "") << skipped[k];
      report << ".\n";
    }
    report << "\n## Convergence order of the force model's integrators\n\n"
           << "The harmonic oscillator against its exact solution (a 1 kg ball on a 100 N/m spring under gravity,\n"
           << "error of its height at t = 1 s), dt = 0.01 s halved four times; the order is the least-squares slope\n"
           << "of log(error) against log(dt). Expected: 1, 1, 2, 2, 4.\n\n"
           << "| integrator | errors (m) at dt = 0.01, 0.005, ... | observed order |\n|---|---|---|\n";
    for (sim::Integrator integrator : {sim::Integrator::explicitEuler, sim::Integrator::symplecticEuler,
                                       sim::Integrator::verlet, sim::Integrator::midpoint, sim::Integrator::rk4}) {
      const analysis::Convergence c = analysis::oscillatorConvergence(integrator, 0.01, 5);
      std::ostringstream errors;
      errors.precision(3);
      for (const analysis::ConvergencePoint& p : c.points) errors << (errors.tellp() > 0 ? ", " : "") << p.error;
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %s | %.2f |\n", std::string(sim::name(integrator)).c_str(),
                    errors.str().c_str(), c.order);
      report << line;
    }
    report << "\n## Closed-form cases (position model)\n\n"
           << "| case | setting | error |\n|---|---|---|\n";
    for (int substeps : {1, 4}) {
      char line[256];
      std::snprintf(line, sizeof line, "| free fall, 2 s, max abs(y - (y0 - g t^2/2)) | %d substeps | %.2e m |\n",
                    substeps, analysis::freeFallError(substeps));
      report << line;
    }
    for (int substeps : {1, 2, 4, 8, 16}) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "| pendulum released at 90 deg, time to the bottom vs sqrt(L/g) K(sin 45 deg) | %d substeps | "
                    "%.2e s |\n",
                    substeps, analysis::pendulumError(substeps));
      report << line;
    }
    for (int iterations : {20, 100, 400}) {
      double strain = 0.0;
      const double distance = analysis::catenaryError(60, iterations, &strain);
      char line[256];
      std::snprintf(line, sizeof line,
                    "| 60-link chain between two pins vs its catenary, max vertical distance | %d iterations | "
                    "%.2e m (worst link stretched %.2f %%) |\n",
                    iterations, distance, 100.0 * strain);
      report << line;
    }
    report << "\nCommand: `drape-cli study " << arguments.input.scene;
    if (arguments.steps) report << " --steps " << *arguments.steps;
    if (arguments.seconds) report << " --time " << *arguments.seconds;
    report << " --repeats " << arguments.repeats;
    if (arguments.gesture) report << " --gesture " << *arguments.gesture;
    if (arguments.choose) report << " --choose " << *arguments.choose;
    if (arguments.noReference) report << " --no-reference";
    for (const std::string& s : arguments.sweeps) report << " --sweep " << s;
    for (const std::string& s : arguments.input.overrides) report << " --set " << s;
    report << " --out-dir " << arguments.outDir << (arguments.report ? " --report " + *arguments.report : "") << "`\n";

    scene::writeFilesAtomically({{directory / "accuracy.csv", csv.str()}, {directory / "accuracy.gp", gp.str()}});
    drawWithGnuplot(directory, "accuracy.gp", "accuracy.png");
    if (arguments.report) scene::writeFileAtomically(*arguments.report, report.str());
    if (!arguments.quiet) std::printf("%s", report.str().c_str());
    return kExitOk;
  } catch (const scene::InputError& error) {
    return badInput(error.what());
  }
}

}  // namespace drape::cli
