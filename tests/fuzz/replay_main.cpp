// The fuzz harnesses without libFuzzer: runs every file of the folders and files named on the
// command line through LLVMFuzzerTestOneInput once, in name order, and says how many it ran. It
// never fails by itself: an input that breaks a harness crashes it (under the sanitizers, with a
// report), and the file it was reading is the last one named on stderr. A path that is not there
// is skipped with a note (a harness without crashers has no crashers folder).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::uint8_t> readAll(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path path = argv[i];
    std::error_code error;
    if (std::filesystem::is_directory(path, error)) {
      std::vector<std::filesystem::path> inFolder;
      for (const auto& entry : std::filesystem::directory_iterator(path)) {
        if (entry.is_regular_file()) inFolder.push_back(entry.path());
      }
      std::sort(inFolder.begin(), inFolder.end());
      files.insert(files.end(), inFolder.begin(), inFolder.end());
    } else if (std::filesystem::is_regular_file(path, error)) {
      files.push_back(path);
    } else {
      std::fprintf(stderr, "replay: %s is not there; skipped\n", path.c_str());
    }
  }
  const auto start = std::chrono::steady_clock::now();
  for (const std::filesystem::path& file : files) {
    std::fprintf(stderr, "replay: %s\n", file.c_str());
    // Exactly as long as the file, on the heap, so that reading past its end is caught.
    const std::vector<std::uint8_t> bytes = readAll(file);
    auto* copy = new std::uint8_t[std::max<std::size_t>(bytes.size(), 1)];
    std::copy(bytes.begin(), bytes.end(), copy);
    LLVMFuzzerTestOneInput(copy, bytes.size());
    delete[] copy;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("replay: %zu inputs run in %.2f s\n", files.size(), seconds);
  return 0;
}
