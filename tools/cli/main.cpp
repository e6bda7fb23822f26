// drape-cli: runs the Drape engine without a window. `drape-cli --help` lists the subcommands.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "drape/scene/input.hpp"

namespace {

using namespace drape::cli;

// CLI11 reads "0x10" as hexadecimal and "010" as octal, and calls "1e3" out of range: a count on
// our command line is decimal digits, and anything else says so.
const CLI::Validator kDecimal(
    [](std::string& text) -> std::string {
      const std::size_t digits = text.rfind('-', 0) == 0 ? 1 : 0;
      const bool ok = text.size() > digits && text.size() <= 18 + digits &&
                      std::all_of(text.begin() + static_cast<std::ptrdiff_t>(digits), text.end(),
                                  [](char c) { return c >= '0' && c <= '9'; });
      if (!ok) return "expected a whole number in decimal digits, got " + drape::scene::printable(text, 40);
      // Leading zeros would be read as octal: "010" is ten.
      const std::size_t first = text.find_first_not_of('0', digits);
      text.erase(digits, (first == std::string::npos ? text.size() - 1 : first) - digits);
      return std::string();
    },
    "INT");

// A number (CLI11's range check alone called "abc" out of range): decimal, finite.
const CLI::Validator kNumber(
    [](std::string& text) -> std::string {
      double value = 0.0;
      const char* end = text.data() + text.size();
      const char* begin = text.data() + (text.rfind('+', 0) == 0 ? 1 : 0);  // "+1" as CLI11 took it
      const auto [at, error] = std::from_chars(begin, end, value);
      if (begin == end || error != std::errc() || at != end || !std::isfinite(value)) {
        return "expected a number, got " + drape::scene::printable(text, 40);
      }
      return std::string();
    },
    "NUMBER");

void addSceneOptions(CLI::App* command, SceneArguments& arguments) {
  command
      ->add_option("scene", arguments.scene,
                   "Scene file, the name of a shipped scene, or a snapshot (NAME.drape.json) to go on from")
      ->required();
  command->add_option("--set", arguments.overrides, "Override a key: path=value (repeatable)");
}

void addLengthOptions(CLI::App* command, std::optional<std::int64_t>& steps, std::optional<double>& seconds) {
  CLI::Option* stepsOption = command->add_option("--steps", steps, "Number of steps (default: the scene's duration)")
                                 ->transform(kDecimal)
                                 ->check(CLI::Range(std::int64_t{0}, std::int64_t{1000000000}));
  command->add_option("--time", seconds, "Simulated seconds instead of --steps")
      ->check(kNumber)
      ->check(CLI::Range(0.0, 1.0e6))
      ->excludes(stepsOption);
}

// --out, --intersections-every/out and --quiet of run and replay.
void addRunOutputs(CLI::App* command, RunArguments& arguments) {
  command->add_option(
      "--out", arguments.outputs,
      "Write the final state (.json), a snapshot the app opens (.drape.json) or the mesh (.obj) (repeatable)");
  CLI::Option* every = command
                           ->add_option("--intersections-every", arguments.intersectionsEvery,
                                        "Count intersecting triangle pairs at step 0, every K steps and the last step")
                           ->transform(kDecimal)
                           ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000000}));
  CLI::Option* out = command->add_option("--intersections-out", arguments.intersectionsOut,
                                         "CSV of the counts: step,time,pairs,skipped");
  every->needs(out);
  out->needs(every);
  command->add_flag("--quiet", arguments.quiet, "Print nothing on success");
}

// --out-dir, --report and --quiet of the studies.
void addReportOptions(CLI::App* command, std::string& outDir, std::optional<std::string>& report, bool& quiet) {
  command->add_option("--out-dir", outDir, "Folder for CSV and picture (default " + outDir + ")");
  command->add_option("--report", report, "Also write a Markdown report here");
  command->add_flag("--quiet", quiet, "Print nothing on success");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"drape-cli: the Drape cloth engine, headless"};
  app.require_subcommand(1);

  SceneArguments validateArguments;
  CLI::App* validateCommand = app.add_subcommand("validate", "Check a scene file; exit 0 if it is valid, 2 if not");
  addSceneOptions(validateCommand, validateArguments);

  RunArguments runArguments;
  CLI::App* runCommand = app.add_subcommand("run", "Simulate a scene and write its final state, mesh or a trace");
  addSceneOptions(runCommand, runArguments.input);
  addLengthOptions(runCommand, runArguments.steps, runArguments.seconds);
  addRunOutputs(runCommand, runArguments);
  CLI::Option* trace = runCommand->add_option("--trace", runArguments.trace, "Trace one particle: column,row");
  runCommand->add_option("--trace-cloth", runArguments.traceCloth, "Which cloth --trace refers to (default 0)")
      ->transform(kDecimal)
      ->check(CLI::Range(0, 1000))
      ->needs(trace);
  CLI::Option* traceOut =
      runCommand->add_option("--trace-out", runArguments.traceOut, "CSV file for --trace: time and position per step");
  trace->needs(traceOut);
  traceOut->needs(trace);
  runCommand->add_option("--gesture", runArguments.gesture, "Play this gesture script while running");

  RunArguments replayArguments;
  CLI::App* replayCommand = app.add_subcommand(
      "replay", "Play a gesture script on a scene and write the final state (run with a gesture, by position)");
  addSceneOptions(replayCommand, replayArguments.input);
  replayCommand->add_option("gesture", replayArguments.gesture, "Gesture script (JSON)")->required();
  addLengthOptions(replayCommand, replayArguments.steps, replayArguments.seconds);
  addRunOutputs(replayCommand, replayArguments);

  RenderArguments renderArguments;
  CLI::App* renderCommand =
      app.add_subcommand("render", "Simulate a scene and draw it off-screen (OSMesa) to PNG pictures");
  addSceneOptions(renderCommand, renderArguments.input);
  addLengthOptions(renderCommand, renderArguments.steps, renderArguments.seconds);
  renderCommand->add_option("--size", renderArguments.size, "Picture size WxH in pixels (default 800x600)");
  renderCommand->add_option("--camera", renderArguments.camera,
                            "auto, front, side, top, or yaw,pitch,distance[,x,y,z] in degrees and metres");
  CLI::Option* renderOut = renderCommand->add_option("--out", renderArguments.out, "PNG of the last step");
  CLI::Option* every = renderCommand->add_option("--every", renderArguments.every, "A PNG every K steps (and step 0)")
                           ->transform(kDecimal)
                           ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000000}));
  CLI::Option* outDir = renderCommand->add_option("--out-dir", renderArguments.outDir, "Folder for the --every frames");
  every->needs(outDir);
  outDir->needs(every);
  renderOut->excludes(every);
  renderCommand->add_flag("--strain", renderArguments.strain, "Colour the cloth by its stretch");
  renderCommand->add_flag("--edges", renderArguments.edges, "Draw the triangles' edges over the cloth");
  renderCommand->add_option("--gesture", renderArguments.gesture, "Play this gesture script (fingers are drawn)");
  renderCommand->add_flag("--quiet", renderArguments.quiet, "Print nothing on success");

  StabilityArguments stabilityArguments;
  CLI::App* stabilityCommand = app.add_subcommand(
      "stability", "Map where each force-model integrator is stable (stiffness x dt) against linear theory");
  addReportOptions(stabilityCommand, stabilityArguments.outDir, stabilityArguments.report, stabilityArguments.quiet);

  FabricArguments fabricArguments;
  CLI::App* fabricCommand = app.add_subcommand(
      "fabric", "The textile lab: every fabric preset in the Peirce cantilever against the heavy elastica");
  addReportOptions(fabricCommand, fabricArguments.outDir, fabricArguments.report, fabricArguments.quiet);

  StudyArguments studyArguments;
  CLI::App* studyCommand =
      app.add_subcommand("study", "Error against run time over configurations of a scene, and integrator orders");
  addSceneOptions(studyCommand, studyArguments.input);
  addLengthOptions(studyCommand, studyArguments.steps, studyArguments.seconds);
  studyCommand->add_option(
      "--sweep", studyArguments.sweeps,
      "path=v1,v2,... (repeatable: every combination runs, but those whose keys do not go together)");
  studyCommand->add_option("--repeats", studyArguments.repeats, "Timed runs per configuration (median)")
      ->transform(kDecimal)
      ->check(CLI::Range(1, 100));
  studyCommand->add_option("--gesture", studyArguments.gesture, "Play this gesture script in every run");
  studyCommand
      ->add_option("--choose", studyArguments.choose,
                   "Mark the cheapest configuration whose worst strain stays within this (0.05 = 5 %)")
      ->check(kNumber)
      ->check(CLI::Range(0.0, 10.0));
  studyCommand->add_flag("--no-reference", studyArguments.noReference,
                         "No reference runs: compare time with worst strain only (much faster)");
  addReportOptions(studyCommand, studyArguments.outDir, studyArguments.report, studyArguments.quiet);

  BenchArguments benchArguments;
  CLI::App* benchCommand = app.add_subcommand(
      "bench", "Time the solver on hang2 (N x N) and more scenes, against the naive baseline; write a report");
  benchCommand->add_option("--sizes", benchArguments.sizes, "hang2 side N, comma-separated (default 64,128,256)")
      ->delimiter(',')
      ->transform(kDecimal)
      ->check(CLI::Range(2, 1024));
  benchCommand->add_option("--threads", benchArguments.threads, "Thread counts (default 1,2)")
      ->delimiter(',')
      ->transform(kDecimal)
      ->check(CLI::Range(1, 64));
  benchCommand
      ->add_option("--naive-iterations", benchArguments.naiveIterations,
                   "The naive baseline's sweeps per frame (default 10,200; 0: no baseline)")
      ->delimiter(',')
      ->transform(kDecimal)
      ->check(CLI::Range(0, 100000));
  benchCommand->add_option("--scenes", benchArguments.scenes, "More scenes to time (default drape-sphere,hang2-tear)")
      ->delimiter(',');
  benchCommand
      ->add_option("--touch-sizes", benchArguments.touchSizes,
                   "The scenes people touch (desk crumple, fold and tear, drape-sphere, table edge) at N x N, "
                   "comma-separated (default 64,128,256; 0: none)")
      ->delimiter(',')
      ->transform(kDecimal)
      ->check(CLI::Range(0, 1024));
  benchCommand
      ->add_option("--touch-cases", benchArguments.touchCases,
                   "Which of the scenes people touch to play, by name (\"desk crumple,desk tear\"; default every one)")
      ->delimiter(',');
  benchCommand
      ->add_option("--touch-budget", benchArguments.touchBudget,
                   "Seconds of stepping a touch case may take; it stops there and says how far it got (default 60)")
      ->check(kNumber)
      ->check(CLI::Range(0.001, 1.0e6));
  benchCommand
      ->add_option("--touch-spread", benchArguments.touchSpread,
                   "More untimed runs of each touch case that played whole, gravity moved by k x 1e-7 of itself, "
                   "for how far the strain and the pairs spread over chance (default 4; 0: none)")
      ->transform(kDecimal)
      ->check(CLI::Range(0, 100));
  benchCommand->add_option("--frames", benchArguments.frames, "Frames per run (default 120)")
      ->transform(kDecimal)
      ->check(CLI::Range(1, 100000));
  benchCommand->add_option("--repeats", benchArguments.repeats, "Timed runs per case (median; default 5)")
      ->transform(kDecimal)
      ->check(CLI::Range(1, 100));
  benchCommand
      ->add_option("--substeps", benchArguments.substeps,
                   "Substeps of Drape's hang2 solver (default: the cheapest sweep that keeps strain within 5 % at "
                   "every frame)")
      ->transform(kDecimal)
      ->check(CLI::Range(1, 1000));
  benchCommand
      ->add_option("--max-stretch", benchArguments.maxStretch,
                   "The most a link of hang2 may stretch that Drape's sweep works to, a fraction of its rest length "
                   "(solver.maxStretch; default hang2.json's; 0: none)")
      ->check(kNumber)
      ->check(CLI::Range(0.0, 1.0));
  benchCommand->add_flag("--quick", benchArguments.quick,
                         "Smoke test: N = 16, 24, 10 frames, one repeat, 10 naive sweeps, touch cases at 8 x 8 for 2 s "
                         "(each unless given)");
  addReportOptions(benchCommand, benchArguments.outDir, benchArguments.report, benchArguments.quiet);

  app.add_subcommand("scenes", "List the shipped scenes");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help
    std::cerr << "drape-cli: error: " << error.what() << " (see drape-cli --help)\n";
    return kExitBadInput;
  }
  try {
    if (*validateCommand) return validate(validateArguments);
    if (*runCommand) return run(runArguments);
    if (*replayCommand) return run(replayArguments);
    if (*renderCommand) return render(renderArguments);
    if (*stabilityCommand) return stability(stabilityArguments);
    if (*fabricCommand) return fabric(fabricArguments);
    if (*studyCommand) return study(studyArguments);
    if (*benchCommand) {
      // --quick shrinks only what was not asked for explicitly.
      if (benchArguments.quick) {
        if (benchCommand->count("--sizes") == 0) benchArguments.sizes = {16, 24};
        if (benchCommand->count("--frames") == 0) benchArguments.frames = 10;
        if (benchCommand->count("--repeats") == 0) benchArguments.repeats = 1;
        if (benchCommand->count("--naive-iterations") == 0) benchArguments.naiveIterations = {10};
        if (benchCommand->count("--touch-sizes") == 0) benchArguments.touchSizes = {8};
        if (benchCommand->count("--touch-budget") == 0) benchArguments.touchBudget = 2.0;
        if (benchCommand->count("--touch-spread") == 0) benchArguments.touchSpread = 0;
      }
      return bench(benchArguments);
    }
    return listScenes();
  } catch (const std::exception& error) {  // a bug, not bad input: say so rather than abort
    std::cerr << "drape-cli: internal error: " << error.what() << "\n";
    return kExitInternal;
  }
}
