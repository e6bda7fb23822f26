#include "touch_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common.hpp"
#include "drape/sim/intersections.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::cli {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kCountEvery = 10;  // frames between intersection counts (untimed)
// A scene refined to N x N keeps its self-contact distance (its cloth's thickness) while that is
// under this share of the lattice's spacing, and takes that share where it is not: a surface
// thicker than about a third of its spacing pairs every primitive with its neighbours' neighbours
// at rest (the desk at 64 x 64, flat, before any finger: 325,363 pairs at 5 mm, 31,374 at 0.3 of
// its 9.5 mm spacing).
constexpr double kThicknessPerSpacing = 0.3;

// The worst stretch of a structural link neither of whose ends a finger holds or a pin keeps.
double freeStrain(const sim::World& world) {
  double worst = 0.0;
  for (const sim::Cloth& cloth : world.cloths()) {
    const std::vector<sim::Real>& w = cloth.state.inverseMass;
    for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
      if (!(c.restLength > 0.0) || w[c.a] == 0.0 || w[c.b] == 0.0) continue;
      const double length = glm::length(cloth.state.position[c.b] - cloth.state.position[c.a]);
      worst = std::max(worst, length / c.restLength - 1.0);
    }
  }
  return worst;
}

}  // namespace

std::vector<TouchCase> touchCases() {
  return {{"desk crumple", "desk", "crumple.json"},
          {"desk fold", "desk", "fold.json"},
          {"desk tear", "desk-tear", "tear.json"},
          {"drape-sphere", "drape-sphere", ""},
          {"table edge", "table", ""}};
}

TouchRow playTouchCase(const TouchCase& c, int n, int threads, double budgetSeconds, double gravityScale) {
  SceneArguments input{c.scene,
                       {"cloths.0.grid.columns=" + std::to_string(n), "cloths.0.grid.rows=" + std::to_string(n)}};
  scene::Scene scene = loadScene(input);
  scene.world.gravity *= gravityScale;
  TouchRow row;
  row.name = c.name;
  row.n = n;
  row.threads = threads;
  sim::SelfCollisionSettings& self = scene.world.selfCollision;
  if (self.enabled) {
    const sim::LatticeSpec& grid = scene.world.cloths.front().lattice;
    const double spacing =
        std::min(grid.width / std::max(grid.columns - 1, 1), grid.height / std::max(grid.rows - 1, 1));
    self.distance = std::min<double>(self.distance, kThicknessPerSpacing * spacing);
    row.distance = self.distance;
  }
  // The shipped gestures, beside the shipped scenes, wherever the bench is run from.
  const std::optional<std::string> gesture =
      c.gesture.empty()
          ? std::nullopt
          : std::optional<std::string>((scene::sceneDirectory().parent_path() / "gestures" / c.gesture).string());
  Playback playback(scene, gesture);
  sim::World& world = playback.world();
  world.setThreads(threads);
  row.frames = static_cast<int>(stepCount(scene, std::nullopt, std::nullopt, playback.script()));
  for (const sim::Cloth& cloth : world.cloths()) row.particles += cloth.state.position.size();

  double stepping = 0.0;
  std::size_t bytes = 0;
  const auto look = [&](bool count) {
    const double strain = freeStrain(world);
    row.freeStrainEnd = strain;
    row.freeStrainWorst = std::max(row.freeStrainWorst, strain);
    bytes = std::max(bytes, world.memoryUse().total());
    if (count) {
      row.pairsEnd = sim::countIntersections(world).pairs;
      row.pairsWorst = std::max(row.pairsWorst, row.pairsEnd);
    }
  };
  for (int frame = 0; frame < row.frames; ++frame) {
    const auto start = Clock::now();
    const sim::StepStatus status = playback.step();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stepping += seconds;
    row.msWorstFrame = std::max(row.msWorstFrame, 1e3 * seconds);
    ++row.framesRun;
    if (status == sim::StepStatus::diverged) {
      row.diverged = true;
      break;
    }
    const bool last = frame + 1 == row.frames || stepping > budgetSeconds;
    look(last || (frame + 1) % kCountEvery == 0);
    if (last) break;
  }
  row.msPerFrame = 1e3 * stepping / std::max(row.framesRun, 1);
  row.stageMs = bench::stageMs(world.profile(), row.framesRun);
  row.bytesPerParticle = static_cast<double>(bytes) / static_cast<double>(std::max<std::size_t>(row.particles, 1));
  row.hash = sim::stateHash(world);
  return row;
}

std::string touchLine(const TouchRow& row) {
  char text[256];
  std::snprintf(text, sizeof text,
                "%-13s %4d x %-4d %2d thread(s) %9.3f ms/frame (%d of %d frames)  free strain worst %7.2f %%  "
                "intersecting pairs worst %zu",
                row.name.c_str(), row.n, row.n, row.threads, row.msPerFrame, row.framesRun, row.frames,
                100.0 * row.freeStrainWorst, row.pairsWorst);
  return text;
}

std::string touchCsv(const std::vector<TouchRow>& rows) {
  std::ostringstream csv;
  csv.precision(9);
  csv << "case,n,particles,threads,distance,frames,frames_run,ms_per_frame,ms_worst_frame,free_strain_end,"
         "free_strain_worst,pairs_end,pairs_worst,bytes_per_particle,diverged\n";
  for (const TouchRow& r : rows) {
    csv << r.name << ',' << r.n << ',' << r.particles << ',' << r.threads << ',' << r.distance << ',' << r.frames << ','
        << r.framesRun << ',' << r.msPerFrame << ',' << r.msWorstFrame << ',' << r.freeStrainEnd << ','
        << r.freeStrainWorst << ',' << r.pairsEnd << ',' << r.pairsWorst << ',' << r.bytesPerParticle << ','
        << (r.diverged ? 1 : 0) << '\n';
  }
  return csv.str();
}

TouchSpread spreadTouchCase(const TouchCase& c, const TouchRow& timed, int runs, int threads, double budgetSeconds) {
  TouchSpread spread;
  spread.name = timed.name;
  spread.n = timed.n;
  spread.freeStrainWorst.push_back(timed.freeStrainWorst);
  spread.freeStrainEnd.push_back(timed.freeStrainEnd);
  spread.pairsWorst.push_back(timed.pairsWorst);
  for (int k = 1; k <= runs; ++k) {
    const TouchRow row = playTouchCase(c, timed.n, threads, budgetSeconds, 1.0 + 1e-7 * k);
    if (row.diverged || row.framesRun < row.frames) {
      ++spread.notWhole;
      continue;
    }
    spread.freeStrainWorst.push_back(row.freeStrainWorst);
    spread.freeStrainEnd.push_back(row.freeStrainEnd);
    spread.pairsWorst.push_back(row.pairsWorst);
  }
  return spread;
}

namespace {

// The middle of `values` (the mean of the two middle ones where there is an even number), and the most.
double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::ranges::sort(values);
  const std::size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}
double most(const std::vector<double>& values) { return values.empty() ? 0.0 : std::ranges::max(values); }

}  // namespace

std::string touchSpreadCsv(const std::vector<TouchSpread>& spreads) {
  std::ostringstream csv;
  csv.precision(9);
  csv << "case,n,run,gravity_scale,free_strain_end,free_strain_worst,pairs_worst\n";
  for (const TouchSpread& s : spreads) {
    for (std::size_t k = 0; k < s.freeStrainWorst.size(); ++k) {
      csv << s.name << ',' << s.n << ',' << k << ',' << (k == 0 ? "1" : "1+" + std::to_string(k) + "e-7") << ','
          << s.freeStrainEnd[k] << ',' << s.freeStrainWorst[k] << ',' << s.pairsWorst[k] << '\n';
    }
  }
  return csv.str();
}

std::string touchSection(const std::vector<TouchRow>& rows, double budgetSeconds,
                         const std::vector<TouchSpread>& spreads) {
  std::ostringstream md;
  md << "## The scenes people touch\n\n"
     << "Each case is a shipped scene with its cloth refined to N x N (the same size and mass), played whole "
        "with its gesture, frame by frame: `desk crumple` is `desk` with `assets/gestures/crumple.json`, "
        "`desk fold` `desk` with `fold.json`, `desk tear` `desk-tear` with `tear.json`, `drape-sphere` and "
        "`table edge` (`table`) fall under gravity. Self-contact keeps the scene's distance (5 mm) where it "
        "is under "
     << format("%.2f", kThicknessPerSpacing)
     << " of the lattice's spacing, and takes that share where it is not (the distance column). One run a "
        "case (a gesture's frames differ from one another, so a frame's time is the mean over the run, and the "
        "worst frame beside it); a run stops once its steps have taken "
     << format("%.0f", budgetSeconds)
     << " s, and then says how many frames it played. Free strain is the worst |x_b - x_a| / r - 1 of a "
        "structural link neither of whose ends a finger holds or a pin keeps, after any frame and at the end. "
        "Intersecting pairs are counted exactly (`sim/intersections.hpp`) every "
     << kCountEvery
     << " frames and at the last, outside the timed part. Bytes per particle: the most the world held at "
        "any count. \"same\": the final positions are the same bit for bit on every thread count that "
        "played as many frames (\"-\": none did, so nothing was compared).\n\n"
     << "| case | N | particles | distance | threads | frames | ms / frame | worst frame | free strain (end) | "
        "worst (any frame) | intersecting pairs (end) | most | bytes / particle | same |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  // "yes" or "**no**" against the other thread counts that played as many frames; "-" where none
  // did (a budget stopped them at different frames): nothing was compared.
  const auto same = [&](const TouchRow& r) -> std::string {
    bool compared = false;
    for (const TouchRow& other : rows) {
      if (&other == &r || other.name != r.name || other.n != r.n || other.framesRun != r.framesRun) continue;
      if (other.hash != r.hash) return "**no**";
      compared = true;
    }
    return compared ? "yes" : "-";
  };
  for (const TouchRow& r : rows) {
    md << "| " << r.name << " | " << r.n << " | " << r.particles << " | "
       << (r.distance > 0.0 ? format("%.2f mm", 1e3 * r.distance) : "off") << " | " << r.threads << " | " << r.framesRun
       << (r.framesRun < r.frames ? " of " + std::to_string(r.frames) : "") << (r.diverged ? " (diverged)" : "")
       << " | " << format("%.2f", r.msPerFrame) << " | " << format("%.1f", r.msWorstFrame) << " | "
       << percent(r.freeStrainEnd) << " | " << percent(r.freeStrainWorst) << " | " << r.pairsEnd << " | "
       << r.pairsWorst << " | " << format("%.0f", r.bytesPerParticle) << " | " << same(r) << " |\n";
  }
  if (!spreads.empty()) {
    md << "\nHow the outcome spreads over chance: each case that played whole again, untimed, with gravity "
          "moved by k x 1e-7 of itself (k = 1, 2, ...; a crumple, a fold or a tear is chaotic, and runs that "
          "differ in the seventh digit end in different piles). Free strain as above, its median and its most "
          "over the runs (the timed one among them); intersecting pairs, the most at any count of any run.\n\n"
       << "| case | N | runs | free strain (end): median | most | worst (any frame): median | most | "
          "intersecting pairs, most |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    for (const TouchSpread& s : spreads) {
      std::size_t pairs = 0;
      for (const std::size_t p : s.pairsWorst) pairs = std::max(pairs, p);
      md << "| " << s.name << " | " << s.n << " | " << s.freeStrainWorst.size()
         << (s.notWhole ? " (" + std::to_string(s.notWhole) + " more not whole)" : "") << " | "
         << percent(median(s.freeStrainEnd)) << " | " << percent(most(s.freeStrainEnd)) << " | "
         << percent(median(s.freeStrainWorst)) << " | " << percent(most(s.freeStrainWorst)) << " | " << pairs << " |\n";
    }
  }
  md << "\nWhere the time goes, ms per frame by stage:\n\n";
  for (const TouchRow& r : rows) {
    md << "- " << r.name << " " << r.n << ", " << r.threads << (r.threads == 1 ? " thread:" : " threads:");
    md << " " << bench::describe(r.stageMs);
    md << "\n";
  }

  // The targets, as measured here.
  const auto find = [&](const std::string& name, int n, int threads) -> const TouchRow* {
    for (const TouchRow& r : rows) {
      if (r.name == name && r.n == n && r.threads == threads) return &r;
    }
    return nullptr;
  };
  md << "\n### Against the targets\n\n| target | measured | met |\n|---|---|---|\n";
  const auto target = [&](const std::string& what, const std::string& measured, bool met) {
    md << "| " << what << " | " << measured << " | " << (met ? "yes" : "**no**") << " |\n";
  };
  const auto whole = [](const TouchRow& r) { return r.framesRun == r.frames && !r.diverged; };
  for (const auto& [n, limit] : {std::pair{128, 10.0}, std::pair{64, 3.0}}) {
    if (const TouchRow* r = find("desk crumple", n, 2)) {
      target(
          "desk crumple " + std::to_string(n) + " with self-contact and no intersections: <= " + format("%.0f", limit) +
              " ms a frame on 2 threads",
          format("%.2f ms", r->msPerFrame) + ", at most " + std::to_string(r->pairsWorst) + " pairs" +
              (whole(*r) ? "" : " (" + std::to_string(r->framesRun) + " of " + std::to_string(r->frames) + " frames)"),
          whole(*r) && r->msPerFrame <= limit && r->pairsWorst == 0);
    }
  }
  double worst = 0.0;
  std::string where;
  bool all = true;
  for (const TouchRow& r : rows) {
    all = all && whole(r);
    if (r.freeStrainWorst >= worst) {
      worst = r.freeStrainWorst;
      where = r.name + " " + std::to_string(r.n);
    }
  }
  for (const TouchSpread& s : spreads) {
    if (most(s.freeStrainWorst) >= worst) {
      worst = most(s.freeStrainWorst);
      where = s.name + " " + std::to_string(s.n) + ", over its runs";
    }
  }
  if (!rows.empty()) {
    target("the worst free edge within 5 % of its rest length through every gesture, at every size",
           percent(worst) + " (" + where + ")" + (all ? "" : "; not every run played whole"), all && worst <= 0.05);
  }
  for (const TouchCase& c : touchCases()) {
    const TouchRow *small = nullptr, *large = nullptr;
    for (const TouchRow& r : rows) {
      if (r.name != c.name || r.threads != 1 || !whole(r)) continue;
      if (!small || r.n < small->n) small = &r;
      if (!large || r.n > large->n) large = &r;
    }
    if (!small || small == large) continue;
    const double growth = (large->msPerFrame / static_cast<double>(large->particles)) /
                          (small->msPerFrame / static_cast<double>(small->particles));
    target(c.name + ": cost per particle from " + std::to_string(small->n) + " to " + std::to_string(large->n) +
               " within 1.3x (1 thread)",
           format("%.2fx", growth), growth <= 1.3);
  }
  double most = 0.0;
  for (const TouchRow& r : rows) {
    if (r.distance > 0.0 && r.bytesPerParticle >= most) {
      most = r.bytesPerParticle;
      where = r.name + " " + std::to_string(r.n);
    }
  }
  if (most > 0.0) {
    target("<= 300 bytes a particle with self-contact", format("%.0f bytes", most) + " (" + where + ")", most <= 300.0);
  }
  return md.str();
}

}  // namespace drape::cli
