// Off-screen pictures from the real drape-cli against reference images (assets/golden), and a
// check that the cloth is actually in the picture. Regenerate the references with tools/golden.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

namespace {

namespace fs = std::filesystem;

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgba;
};

Image load(const fs::path& file) {
  Image image;
  int channels = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> data(
      stbi_load(file.c_str(), &image.width, &image.height, &channels, 4), stbi_image_free);
  if (data) image.rgba.assign(data.get(), data.get() + static_cast<std::size_t>(image.width) * image.height * 4);
  return image;
}

// A pixel differs when any channel is off by more than kChannelTolerance; a picture matches when at
// most kAllowedShare of its pixels differ (rasterisers may move an edge by a pixel).
constexpr int kChannelTolerance = 24;
constexpr double kAllowedShare = 0.005;

// Counts differing pixels and paints them red in `diff` (the rest a dim copy of the reference).
std::size_t compare(const Image& actual, const Image& expected, Image& diff) {
  diff = expected;
  std::size_t differing = 0;
  for (std::size_t i = 0; i < expected.rgba.size(); i += 4) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(actual.rgba[i + c] - expected.rgba[i + c]));
    const bool differs = worst > kChannelTolerance;
    differing += differs;
    for (int c = 0; c < 3; ++c) {
      diff.rgba[i + c] = static_cast<unsigned char>(differs ? (c == 0 ? 255 : 0) : expected.rgba[i + c] / 3);
    }
    diff.rgba[i + 3] = 255;
  }
  return differing;
}

// Share of strongly coloured pixels: the table and the sky are near grey, the cloth (either side,
// or its strain colours) is saturated, but for the gingham's white squares.
double clothShare(const Image& image) {
  std::size_t coloured = 0;
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    const int hi = std::max({image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]});
    const int lo = std::min({image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]});
    coloured += hi > 40 && (hi - lo) * 100 > hi * 35;
  }
  return static_cast<double>(coloured) / static_cast<double>(image.rgba.size() / 4);
}

struct Case {
  std::string name;
  double minimumClothShare;  // fraction of the picture
  std::string arguments;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> cases() {
  std::vector<Case> result;
  std::ifstream in(fs::path(DRAPE_ASSET_DIR) / "golden" / "cases.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    // A malformed line becomes a case that fails (a minimum share above 100 %), not an abort.
    const double share = second == std::string::npos ? 200.0 : std::strtod(line.substr(first + 1).c_str(), nullptr);
    result.push_back(
        {line.substr(0, first), share / 100.0, second == std::string::npos ? "" : line.substr(second + 1)});
  }
  return result;
}

fs::path outputDirectory() {
  const fs::path directory = fs::current_path() / "golden-out";
  fs::create_directories(directory);
  return directory;
}

int render(const std::string& arguments, const fs::path& out) {
  // Built by appending: GCC 12 at -O3 warns falsely (-Wrestrict) on a chain of + here. Run from the
  // source tree, as tools/golden runs, so a case's paths (assets/gestures/...) are found.
  std::string command = "cd '";
  command.append(fs::path(DRAPE_ASSET_DIR).parent_path().string()).append("' && '");
  command.append(DRAPE_CLI)
      .append("' render ")
      .append(arguments)
      .append(" --quiet --out '")
      .append(out.string())
      .append("'");
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class Golden : public ::testing::TestWithParam<Case> {};

TEST_P(Golden, MatchesTheReferenceAndShowsTheCloth) {
  const Case& c = GetParam();
  const fs::path actualFile = outputDirectory() / (c.name + ".png");
  ASSERT_EQ(render(c.arguments, actualFile), 0) << c.arguments;
  const Image actual = load(actualFile);
  const Image expected = load(fs::path(DRAPE_ASSET_DIR) / "golden" / (c.name + ".png"));
  ASSERT_FALSE(expected.rgba.empty()) << "no reference image: run tools/golden";
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);

  EXPECT_GT(clothShare(actual), c.minimumClothShare) << "the cloth is missing from " << actualFile;

  Image diff;
  const std::size_t differing = compare(actual, expected, diff);
  const auto allowed = static_cast<std::size_t>(kAllowedShare * actual.width * actual.height);
  if (differing > allowed) {
    const fs::path diffFile = outputDirectory() / (c.name + ".diff.png");
    stbi_write_png(diffFile.c_str(), diff.width, diff.height, 4, diff.rgba.data(), diff.width * 4);
    ADD_FAILURE() << differing << " pixels differ (allowed " << allowed << "): see " << actualFile << " and "
                  << diffFile;
  }
}

INSTANTIATE_TEST_SUITE_P(References, Golden, ::testing::ValuesIn(cases()), [](const auto& testInfo) {
  std::string name = testInfo.param.name;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
});

TEST(GoldenChecks, AnEmptySceneFailsTheClothCheck) {
  const fs::path scene = outputDirectory() / "empty.json";
  std::ofstream(scene) << R"({"cloths": []})";
  const fs::path picture = outputDirectory() / "empty.png";
  std::string arguments = "'";
  arguments.append(scene.string()).append("' --size 160x120 --steps 1");
  ASSERT_EQ(render(arguments, picture), 0);
  EXPECT_LT(clothShare(load(picture)), 0.001);
}

TEST(GoldenChecks, TheComparisonTellsDifferentScenesApart) {
  const fs::path picture = outputDirectory() / "hang-as-curtain.png";
  ASSERT_EQ(render("hang --size 320x240", picture), 0);
  Image diff;
  const Image hang = load(picture), curtain = load(fs::path(DRAPE_ASSET_DIR) / "golden" / "curtain.png");
  ASSERT_EQ(hang.rgba.size(), curtain.rgba.size());
  EXPECT_GT(compare(hang, curtain, diff), static_cast<std::size_t>(kAllowedShare * 320 * 240));
}

}  // namespace
