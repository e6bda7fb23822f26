// The fixture of the whole-program tests: a fresh folder per test and the real drape-cli binary
// run in a shell, its exit code and output captured.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace drape::test {

namespace fs = std::filesystem;

struct Result {
  int exitCode;  // 124: still running when the run's time limit passed (a hang)
  std::string out;
  std::string err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ =
        fs::temp_directory_path() / ("drape-cli-test-" + std::string(test->name()) + "-" + std::to_string(::getpid()));
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }

  fs::path file(const std::string& name) const { return directory_ / name; }

  fs::path write(const std::string& name, const std::string& contents) const {
    std::ofstream(file(name), std::ios::binary) << contents;
    return file(name);
  }

  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

  // Runs drape-cli with `arguments` (shell words), capturing stdout and stderr. With a limit, a run
  // still going after that many seconds is stopped and reports exit code 124: for the inputs that
  // once made it wait forever. (A limit is a generous bound on a hang, never a speed target.)
  Result run(const std::string& arguments, int limitSeconds = 0) const {
    const fs::path out = file("stdout.txt"), err = file("stderr.txt");
    const std::string limit = limitSeconds > 0 ? "timeout -k 5 " + std::to_string(limitSeconds) + " " : "";
    const std::string command =
        limit + "'" + DRAPE_CLI + "' " + arguments + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(out), read(err)};
  }

  // A minimal valid scene with one 4 x 3 cloth.
  static nlohmann::json scene() {
    return nlohmann::json::parse(R"({"solver": {"dt": 0.01}, "cloths": [{"grid": {"columns": 4, "rows": 3,
      "width": 0.3, "height": 0.2}, "origin": [0, 1, 0], "pins": [{"particle": [0, 0]}]}]})");
  }

  fs::path directory_;
};

inline void expectOneLineError(const Result& result, int exitCode, const std::string& fragment) {
  EXPECT_EQ(result.exitCode, exitCode) << result.err;
  EXPECT_NE(result.err.find(fragment), std::string::npos) << "stderr: " << result.err.substr(0, 2000);
  EXPECT_EQ(result.err.rfind("drape-cli: error: ", 0), 0u) << result.err.substr(0, 2000);
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err.substr(0, 2000);
}

}  // namespace drape::test
