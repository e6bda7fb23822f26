// drape-cli's subcommands. Each returns the process exit code:
//   0 success, 1 the simulation diverged, 2 bad input (scene, option, unwritable output),
//   3 an internal error (a bug: please report it).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace drape::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitDiverged = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInternal = 3;
inline constexpr double kMaxSteps = 1.0e9;  // per run

struct SceneArguments {
  std::string scene;                   // path, or the name of a shipped scene
  std::vector<std::string> overrides;  // --set path=value
};

struct RunArguments {
  SceneArguments input;
  std::optional<std::int64_t> steps;
  std::optional<double> seconds;
  std::vector<std::string> outputs;  // .json (state) or .obj (mesh)
  std::optional<std::string> trace;  // "column,row"
  int traceCloth = 0;
  std::optional<std::string> traceOut;
  std::optional<std::string> gesture;              // a gesture script played while running
  std::optional<std::int64_t> intersectionsEvery;  // count intersecting triangle pairs every K steps ...
  std::optional<std::string> intersectionsOut;     // ... into this CSV
  bool quiet = false;
};

struct RenderArguments {
  SceneArguments input;
  std::optional<std::int64_t> steps;
  std::optional<double> seconds;
  std::string size = "800x600";        // WxH pixels
  std::string camera = "auto";         // a preset or yaw,pitch,distance[,x,y,z]
  std::optional<std::string> out;      // one picture of the last step
  std::optional<std::int64_t> every;   // a picture every K steps ...
  std::optional<std::string> outDir;   // ... into this folder
  bool strain = false;                 // strain colour map
  bool edges = false;                  // the triangles' edges over the surface
  std::optional<std::string> gesture;  // a gesture script played while running
  bool quiet = false;
};

struct StabilityArguments {
  std::string outDir = "stability";   // CSV, gnuplot script and picture
  std::optional<std::string> report;  // Markdown report
  bool quiet = false;
};

struct FabricArguments {
  std::string outDir = "fabric";      // CSV
  std::optional<std::string> report;  // Markdown report
  bool quiet = false;
};

struct StudyArguments {
  SceneArguments input;
  std::optional<std::int64_t> steps;
  std::optional<double> seconds;
  std::vector<std::string> sweeps;  // path=v1,v2,...
  int repeats = 3;
  std::optional<std::string> gesture;  // played in every run
  std::optional<double> choose;        // mark the cheapest run whose worst strain is within this
  bool noReference = false;            // skip the reference runs (no trajectory error)
  std::string outDir = "accuracy";
  std::optional<std::string> report;
  bool quiet = false;
};

struct BenchArguments {
  std::vector<int> sizes{64, 128, 256};                           // hang2 N
  std::vector<int> threads{1, 2};                                 // Drape's solver on this many threads
  std::vector<int> naiveIterations{10, 200};                      // the naive baseline's sweeps per frame
  std::vector<std::string> scenes{"drape-sphere", "hang2-tear"};  // more scenes (Drape's solver only)
  std::vector<int> touchSizes{64, 128, 256};  // the scenes people touch at N x N (touch_bench.hpp); 0: none
  double touchBudget = 60.0;                  // s of stepping a touch case may take before it stops
  int touchSpread = 4;  // more untimed runs of each whole touch case, gravity moved by k x 1e-7 (touch_bench.hpp)
  std::vector<std::string> touchCases;  // by name ("desk crumple"); empty: every one
  int frames = 120;
  int repeats = 5;                   // timed runs (median); fewer once a case has taken 20 s
  int substeps = 0;                  // Drape's hang2 substeps (of one sweep); 0: the cheapest sweep within 5 % strain
  std::optional<double> maxStretch;  // Drape's hang2 sweep works to this (solver.maxStretch); unset: the scene's
  bool quick = false;  // a smoke test: small sizes, few frames (main.cpp applies it to the options not given)
  std::string outDir = "performance";
  std::optional<std::string> report;
  bool quiet = false;
};

int validate(const SceneArguments& arguments);
int bench(const BenchArguments& arguments);
int study(const StudyArguments& arguments);
int stability(const StabilityArguments& arguments);
int fabric(const FabricArguments& arguments);
int render(const RenderArguments& arguments);
int run(const RunArguments& arguments);
int listScenes();

}  // namespace drape::cli
