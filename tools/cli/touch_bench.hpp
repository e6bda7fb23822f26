// drape-cli bench: the scenes people touch (the desk's crumple, fold and tear, the drape over a
// sphere, the cloth over a table's edge) at fabric resolution, each played whole with its gesture:
// time per frame and per stage, the strain of the particles no finger holds, the triangle pairs
// that pass through each other, and the bytes a particle costs.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "drape/bench/measure.hpp"

namespace drape::cli {

struct TouchCase {
  std::string name;     // "desk crumple"
  std::string scene;    // a shipped scene
  std::string gesture;  // a shipped gesture script (assets/gestures), or "" for none
};

// The cases the bench plays by default.
std::vector<TouchCase> touchCases();

struct TouchRow {
  std::string name;
  int n = 0;  // the cloth's grid, n x n
  int threads = 1;
  std::size_t particles = 0;
  double distance = 0.0;  // the self-contact distance played, m (0: the scene has no self-contact)
  int frames = 0;         // of the case
  int framesRun = 0;      // fewer where the time budget ran out
  double msPerFrame = 0.0;
  double msWorstFrame = 0.0;
  std::vector<bench::StageMs> stageMs;  // per frame, by stage
  double freeStrainEnd = 0.0;           // structural links with no end held or pinned: |x_b - x_a| / r - 1
  double freeStrainWorst = 0.0;
  std::size_t pairsEnd = 0;    // intersecting triangle pairs
  std::size_t pairsWorst = 0;  // over the counts (every kCountEvery frames and the last)
  double bytesPerParticle = 0.0;
  bool diverged = false;
  std::uint64_t hash = 0;  // the final state's (sim::stateHash): 1 and N threads must agree
};

// Plays `c` at n x n on `threads` threads, for at most `budgetSeconds` of stepping, with the scene's
// gravity times `gravityScale`.
TouchRow playTouchCase(const TouchCase& c, int n, int threads, double budgetSeconds, double gravityScale = 1.0);

// How a case's outcome spreads over chance: the free strain and the intersecting pairs of its timed
// run and of `runs` more, each with gravity moved by k x 1e-7 of itself (k = 1 .. runs). A crumple,
// a fold or a tear is chaotic: runs that differ in the seventh digit end in different piles, and one
// run's worst link says little.
struct TouchSpread {
  std::string name;
  int n = 0;
  std::vector<double> freeStrainWorst;  // a run each, the timed one first
  std::vector<double> freeStrainEnd;
  std::vector<std::size_t> pairsWorst;
  int notWhole = 0;  // the more runs that a budget stopped or that diverged (left out above)
};
// Plays the more runs of the timed run `timed` (which must have played whole) on `threads` threads.
TouchSpread spreadTouchCase(const TouchCase& c, const TouchRow& timed, int runs, int threads, double budgetSeconds);

// The report's section (Markdown), its CSV, and a one-line summary for the console.
std::string touchSection(const std::vector<TouchRow>& rows, double budgetSeconds,
                         const std::vector<TouchSpread>& spreads = {});
std::string touchCsv(const std::vector<TouchRow>& rows);
std::string touchSpreadCsv(const std::vector<TouchSpread>& spreads);
std::string touchLine(const TouchRow& row);

}  // namespace drape::cli
