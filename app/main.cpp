// drape: the desktop app. `drape --help` lists its options; docs/app.md its bindings.
#include <cctype>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "app.hpp"
#include "drape/scene/error.hpp"

namespace {

// `text` read whole as an integer, or nothing where it is not one; `tooLarge` says whether it was
// digits past what a long long holds.
std::optional<long long> wholeNumber(const std::string& text, bool& tooLarge) {
  tooLarge = false;
  std::size_t used = 0;
  long long value = 0;
  try {
    value = std::stoll(text, &used);
  } catch (const std::out_of_range&) {
    tooLarge = true;
    return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size()) return std::nullopt;
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  drape::app::AppOptions options;
  CLI::App cli{"drape: an interactive cloth simulator you touch"};
  cli.add_option("scene", options.scene, "Scene file, shipped scene name, or snapshot (*.drape.json); default desk");
  cli.add_option("--replay", options.replay, "Play this gesture script as touch events pushed through SDL");
  cli.add_option("--record", options.record, "At exit, write what the fingers did as a gesture script");
  std::vector<std::pair<std::string, std::string>> screenshots;
  cli.add_option("--screenshot-after", screenshots,
                 "N FILE: after frame N, write the window to FILE (PNG); repeatable");
  cli.add_option("--exit-after", options.exitAfter, "Quit after N frames")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000000}));
  cli.add_option(
      "--out", options.out,
      "At exit, write the final state (JSON, as drape-cli run --out), or a snapshot the app opens (NAME.drape.json)");
  // A size that is not a whole number says so (the range check alone called "abc" out of range).
  const CLI::Validator whole(
      [](std::string& text) {
        bool tooLarge = false;
        // (Digits far out of the range: the range check says so.)
        return wholeNumber(text, tooLarge) || tooLarge
                   ? std::string()
                   : drape::scene::printable(text, 80) + ": expected a whole number";
      },
      "");
  cli.add_option("--width", options.width, "Window width in points")->check(whole)->check(CLI::Range(64, 16384));
  cli.add_option("--height", options.height, "Window height in points")->check(whole)->check(CLI::Range(64, 16384));
  cli.add_option("--threads", options.threads, "Simulation threads (default: every core, at most 8)")
      ->check(CLI::Range(1, 8));
  cli.add_option("--render-scale", options.renderScale,
                 "Draw the scene at this fraction of the window's width and height, 0.5 to 1 (default: as many "
                 "pixels as keep 60 fps)")
      ->check(CLI::Range(0.5, 1.0));
  cli.add_flag("--timings", options.timings,
               "At exit, print the median milliseconds of a frame and of its parts (simulation, scene, panels, swap)");
  try {
    cli.parse(argc, argv);
    for (const auto& [count, file] : screenshots) {
      bool tooLarge = false;
      const long long frames = wholeNumber(count, tooLarge).value_or(0);
      if (frames < 1) {
        throw CLI::ValidationError("--screenshot-after",
                                   drape::scene::printable(count, 80) + ": expected a frame count of at least 1");
      }
      if (options.exitAfter && frames > *options.exitAfter) {
        throw CLI::ValidationError("--screenshot-after",
                                   drape::scene::printable(count, 80) + ": the app quits after frame " +
                                       std::to_string(*options.exitAfter) + " (--exit-after), before it");
      }
      std::string extension = std::filesystem::path(file).extension().string();
      for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (extension != ".png") {
        throw CLI::ValidationError("--screenshot-after",
                                   drape::scene::printable(file, 200) + ": expected a .png file (it writes PNG)");
      }
      options.screenshots.emplace_back(frames, file);
    }
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return cli.exit(error);
    std::cerr << "drape: error: " << error.what() << " (see drape --help)\n";
    return 2;
  }
  try {
    return drape::app::runApp(options);
  } catch (const std::exception& error) {
    std::cerr << "drape: internal error: " << error.what() << "\n";
    return 3;
  }
}
