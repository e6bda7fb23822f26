// Hostile input and output, through the real drape-cli binary: each case once crashed it, hung it,
// blew up its memory or clobbered a file. Each must end in exit 0 or a one-line error with exit 2,
// leaving nothing half-written and nothing overwritten that was not asked for.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/types.h>

#include <string>

#include "cli_fixture.hpp"

namespace {

using namespace drape::test;

std::string repeat(const std::string& piece, int times) {
  std::string text;
  for (int i = 0; i < times; ++i) text += piece;
  return text;
}

bool isFifo(const fs::path& path) {
  struct stat status {};
  return ::lstat(path.c_str(), &status) == 0 && S_ISFIFO(status.st_mode);
}

// ---- --set ------------------------------------------------------------------------------------

TEST_F(Cli, ASetValueNestedDeeperThanAFileMayBeIsRefused) {
  // 60,000 levels: a segmentation fault when the value was copied and printed recursively.
  const Result result = run("validate hang --set 'solver.x=" + repeat("[", 60000) + repeat("]", 60000) + "'");
  expectOneLineError(result, 2, "nested more than 64 levels deep");
}

TEST_F(Cli, ASetPathOfThousandsOfKeysIsRefused) {
  std::string path = "a";
  for (int i = 0; i < 60000; ++i) path += ".a";
  expectOneLineError(run("validate hang --set " + path + "=1"), 2, "nested more than 64 levels deep");
  // The message quotes the assignment, but not all of it.
  EXPECT_LT(run("validate hang --set " + path + "=1").err.size(), 300u);
}

TEST_F(Cli, ASetValueWithAKeyTwiceIsRefusedAsInAFile) {
  expectOneLineError(run(R"(validate hang --set 'solver={"dt": 0.01, "dt": 0.5}')"), 2,
                     "--set solver={\"dt\": 0.01, \"dt\": 0.5}: key \"dt\" appears twice in one object");
}

// ---- input files ------------------------------------------------------------------------------

TEST_F(Cli, AFifoAsASceneOrGestureIsRefusedAtOnce) {
  // Opened for reading, a FIFO with no writer waited forever.
  ASSERT_EQ(::mkfifo(file("scene.json").c_str(), 0600), 0);
  expectOneLineError(run("validate '" + file("scene.json").string() + "'", 60), 2,
                     "scene.json: cannot open the scene file: it is not a regular file");
  expectOneLineError(run("replay hang '" + file("scene.json").string() + "'", 60), 2,
                     "scene.json: cannot open the gesture script: it is not a regular file");
}

TEST_F(Cli, AFolderOrADeviceAsASceneIsRefusedByName) {
  expectOneLineError(run("validate '" + directory_.string() + "'"), 2, "cannot open the scene file: it is a folder");
  expectOneLineError(run("validate /dev/zero"), 2, "/dev/zero: cannot open the scene file: it is not a regular file");
}

TEST_F(Cli, ASceneNameTheFileSystemRefusesIsBadInputNotAnInternalError) {
  // A component over 255 bytes: the file system's "name too long" once escaped as exit 3.
  expectOneLineError(run("validate " + repeat("x", 300) + ".json"), 2, "cannot open the scene file");
}

TEST_F(Cli, AFileLargerThanItsKindsLimitIsRefusedBeforeItIsRead) {
  // 65 MiB of nothing (a sparse file: no disk, no time to write), over the 64 MiB scene limit.
  const fs::path big = write("big.json", "");
  fs::resize_file(big, std::uintmax_t{65} << 20);
  expectOneLineError(run("validate '" + big.string() + "'"), 2,
                     "big.json: cannot open the scene file: it is larger than the limit of 64 MiB");
}

TEST_F(Cli, AMillionGestureEventsAreReadInLinearTime) {
  // 1,000,001 events, one over the limit: the parser once rescanned the array at every element
  // (955 s). Now the limit error comes after one pass. (The bound is a hang guard, not a target.)
  std::string gesture = R"({"events": [)";
  gesture.reserve(40'000'000);
  for (int i = 0; i <= 1'000'000; ++i) {
    gesture += i ? "," : "";
    gesture += R"({"time": 0, "type": "up", "finger": 0})";
  }
  gesture += "]}";
  const fs::path script = write("long.json", gesture);
  expectOneLineError(run("replay hang '" + script.string() + "'", 300), 2,
                     "long.json: events: expected an array of at most 1000000 elements");
}

TEST_F(Cli, MoreFingersDownAtOnceThanTheLimitIsBadInput) {
  // Every finger was compared with every other each step: 10,000 fingers took 0.8 s a step.
  nlohmann::json events = nlohmann::json::array();
  for (int finger = 0; finger <= 256; ++finger) {
    events.push_back({{"time", 0.0}, {"type", "down"}, {"finger", finger}, {"at", {0.0, 1.0, 0.0}}});
  }
  const fs::path script = write("hands.json", nlohmann::json{{"events", events}}.dump());
  expectOneLineError(run("replay hang '" + script.string() + "'"), 2,
                     "hands.json: events.256.finger: expected at most 256 fingers down at once, got 256");
  // Lifted fingers do not count.
  for (int finger = 0; finger <= 256; ++finger) events.push_back({{"time", 0.1}, {"type", "up"}, {"finger", finger}});
  events.push_back({{"time", 0.2}, {"type", "down"}, {"finger", 0}, {"at", {0.0, 1.0, 0.0}}});
  nlohmann::json fine = events;
  fine.erase(256);  // 256 down, all up, one down again
  write("hands.json", nlohmann::json{{"events", fine}}.dump());
  EXPECT_EQ(run("replay hang '" + script.string() + "' --steps 15").exitCode, 0);
}

TEST_F(Cli, MessagesQuoteAtMostALineOfWhatTheyRead) {
  // The parser's message quotes the token it was reading: 10 MB of it, ending in a byte that is not
  // UTF-8, went to the terminal whole.
  write("bad.json", "{\"" + std::string(10'000'000, 'a') + "\xff\": 1}");
  const Result malformed = run("validate '" + file("bad.json").string() + "'");
  expectOneLineError(malformed, 2, "bad.json: malformed JSON: ");
  EXPECT_LT(malformed.err.size(), 600u);
  EXPECT_EQ(malformed.err.find('\xff'), std::string::npos);
  // And an unknown key is named, not recited.
  write("bad.json", "{\"" + std::string(10'000'000, 'k') + "\": 1}");
  const Result unknown = run("validate '" + file("bad.json").string() + "'");
  expectOneLineError(unknown, 2, "bad.json: kkkk");
  EXPECT_NE(unknown.err.find("...: unknown key"), std::string::npos) << unknown.err.substr(0, 300);
  EXPECT_LT(unknown.err.size(), 600u);
}

TEST_F(Cli, ALatticeTooFineForItsPrecisionNamesItsKey) {
  expectOneLineError(run("validate hang --set cloths.0.grid.width=1e-30"), 2,
                     "hang.json: cloths.0.grid.width: the lattice spacing is too fine");
}

// ---- the command line -------------------------------------------------------------------------

TEST_F(Cli, CountsAreDecimalDigits) {
  // "0x10" ran 16 steps (hexadecimal), "010" 8 (octal), and "1e3" was "not in range".
  const fs::path out = file("s.json");
  expectOneLineError(run("run hang --steps 0x10 --out '" + out.string() + "'"), 2,
                     "--steps: expected a whole number in decimal digits, got 0x10");
  expectOneLineError(run("run hang --steps 1e3 --out '" + out.string() + "'"), 2,
                     "--steps: expected a whole number in decimal digits, got 1e3");
  expectOneLineError(run("bench --sizes 16,0x20 --quick"), 2, "--sizes: expected a whole number in decimal digits");
  EXPECT_FALSE(fs::exists(out));
  const Result octal = run("run hang --steps 010 --out '" + out.string() + "'");
  ASSERT_EQ(octal.exitCode, 0) << octal.err;
  EXPECT_EQ(nlohmann::json::parse(read(out))["steps"], 10);
}

TEST_F(Cli, AFileOfAnotherKindIsNamedForWhatItIs) {
  // A scene or a snapshot given as a gesture script: said so, not "cloths: unknown key".
  const fs::path snapshot = file("s.drape.json");
  ASSERT_EQ(run("run desk --steps 1 --quiet --out '" + snapshot.string() + "'").exitCode, 0);
  const std::string scene = std::string(DRAPE_ASSET_DIR) + "/scenes/desk.json";
  expectOneLineError(run("replay desk '" + scene + "'"), 2, scene + ": a scene, not a gesture script");
  expectOneLineError(run("replay desk '" + snapshot.string() + "'"), 2,
                     snapshot.string() + ": a snapshot, not a gesture script");
}

// ---- OBJ colliders ----------------------------------------------------------------------------

class CliMesh : public Cli {
 protected:
  Result validateWith(const std::string& objFile) {
    write("mesh.json", R"({"colliders": [{"type": "mesh", "file": ")" + objFile + R"("}]})");
    return run("validate '" + file("mesh.json").string() + "'", 60);
  }
};

TEST_F(CliMesh, AVertexFarOutIsBadInput) {
  // 1e308 m made the collider's grid NaN, and NaN to int ended in exit 3.
  write("far.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1e308\nf 1 2 3\n");
  expectOneLineError(validateWith("far.obj"), 2,
                     "mesh.json: colliders.0.file: cannot use the OBJ file " + file("far.obj").string() +
                         ": vertex 3 lies beyond +-10000 m");
}

TEST_F(CliMesh, AMaterialLibraryIsNeverOpened) {
  // `mtllib` was followed to any path: a FIFO there blocked forever, /dev/zero filled memory.
  ASSERT_EQ(::mkfifo(file("blocks.mtl").c_str(), 0600), 0);
  write("box.obj", "mtllib blocks.mtl\nmtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n");
  const Result result = validateWith("box.obj");
  EXPECT_EQ(result.exitCode, 0) << result.err;
}

TEST_F(CliMesh, AFolderOrADeviceAsTheMeshSaysWhatItIs) {
  // Both were "it does not exist".
  fs::create_directories(file("folder.obj"));
  expectOneLineError(validateWith("folder.obj"), 2, "folder.obj: it is a folder");
  expectOneLineError(validateWith("/dev/zero"), 2, "/dev/zero: it is not a regular file");
}

// ---- outputs ----------------------------------------------------------------------------------

TEST_F(Cli, AFifoOrDeviceAsAnOutputIsRefusedNotReplaced) {
  // The output was renamed over it: a FIFO (or /dev/null, as root) became a plain file.
  ASSERT_EQ(::mkfifo(file("pipe.json").c_str(), 0600), 0);
  expectOneLineError(run("run hang --steps 2 --out '" + file("pipe.json").string() + "'", 60), 2,
                     "pipe.json: cannot write: it is not a regular file (a device, FIFO or socket)");
  EXPECT_TRUE(isFifo(file("pipe.json")));
  EXPECT_EQ(std::distance(fs::directory_iterator(directory_), fs::directory_iterator{}), 3);  // + stdout, stderr
}

TEST_F(Cli, ALinkPlantedAtTheTemporaryNameIsNotFollowed) {
  // The temporary was "OUTPUT.part", opened following links: a link planted there had its target
  // overwritten with the state.
  const fs::path victim = write("victim.txt", "keep me");
  fs::create_symlink(victim, file("s.json.part"));
  const Result result = run("run hang --steps 2 --out '" + file("s.json").string() + "'");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(read(victim), "keep me");
  EXPECT_EQ(nlohmann::json::parse(read(file("s.json")))["steps"], 2);
  EXPECT_TRUE(fs::is_symlink(file("s.json.part")));  // left as it was
}

TEST_F(Cli, AnOutputNameOf255CharactersIsWritten) {
  // The temporary name added ".part" past the 255-byte limit: "the directory is missing".
  const fs::path out = file(repeat("y", 250) + ".json");
  const Result result = run("run hang --steps 2 --out '" + out.string() + "'");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(nlohmann::json::parse(read(out))["steps"], 2);
}

TEST_F(Cli, AFrameSequenceThatDivergesWritesNoFramesAndKeepsTheOldOnes) {
  const fs::path frames = file("frames");
  fs::create_directories(frames);
  const fs::path old = frames / "frame-000000.png";
  std::ofstream(old) << "an old frame";
  const Result result =
      run(std::string("render '") + DRAPE_ASSET_DIR + "/extreme/stiff-springs.json' --every 1 --out-dir '" +
              frames.string() + "' --size 64x48",
          120);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("nothing written"), std::string::npos) << result.err;
  EXPECT_EQ(read(old), "an old frame");
  EXPECT_EQ(std::distance(fs::directory_iterator(frames), fs::directory_iterator{}), 1);
}

TEST_F(Cli, AnOutputFolderNameIsNeverReadAsACommand) {
  // The picture was drawn by a shell command built from --out-dir: a quote broke it, and $(...)
  // in it ran.
  const std::string name = "it's $(touch pwned)";
  const Result result = run("study chain --steps 5 --no-reference --sweep solver.substeps=1,4 --quiet --out-dir \"" +
                            (directory_ / "it's \\$(touch pwned)").string() + "\"");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(fs::is_regular_file(directory_ / name / "accuracy.png"));
  EXPECT_GT(fs::file_size(directory_ / name / "accuracy.png"), 1000u);
  EXPECT_FALSE(fs::exists(directory_ / "pwned"));
  EXPECT_FALSE(fs::exists(directory_ / name / "pwned"));
  EXPECT_FALSE(fs::exists("pwned"));
}

}  // namespace
