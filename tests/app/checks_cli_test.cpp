// What vmpray checks before its work and how it says so: every output path
// before the scene is read, `--stats -` as standard output, the system's
// reason for a file it cannot open, one wording, one range and one exit
// status for each kind of bad argument.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "app/output_check.hpp"
#include "app/wording.hpp"
#include "tests/support/command_line.hpp"
#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

using test::Outcome;

class Checks : public test::ScratchTest {
 protected:
  Checks() : ScratchTest("vmpray_checks_") {}
  Outcome run(const std::string& args) { return run_vmpray(args); }
  static std::size_t lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }
  // A scene that fails on its first line: a run that reads it cannot get past it.
  void write_bad_scene() { std::ofstream(dir_ / "bad.nff") << "bogus\n"; }
};

const char* kTinyScene = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 0.1 resolution 8 8\nl 0 0 5\ns 0 0 0 1\n";

// Each output that cannot be written is refused by its option, with the
// system's reason, before the scene is read (here one that would fail):
// no render is spent on an image that would be lost.
TEST_F(Checks, EveryOutputIsCheckedBeforeTheSceneIsRead) {
  write_bad_scene();
  fs::create_directory(dir_ / "adir");
  std::ofstream(dir_ / "file") << "a file\n";
  const std::pair<std::string, std::string> refused[] = {
      {"-o nope/x.png", "--output: cannot write 'nope/x.png': nope: No such file or directory"},
      {"-o adir/x.png --stats adir", "--stats: cannot write 'adir': Is a directory"},
      {"-o x.png --tiles file/t.csv", "--tiles: cannot write 'file/t.csv': file: Not a directory"},
      {"-o x.png --machine-svg nope/m.svg", "--machine-svg: cannot write 'nope/m.svg': nope: No such file or directory"},
      {"-o x.png --ownership nope/o.png", "--ownership: cannot write 'nope/o.png': nope: No such file or directory"},
      {"-o x.png --timeline nope/t.svg", "--timeline: cannot write 'nope/t.svg': nope: No such file or directory"},
      {"-o x.png --report nope/r.html", "--report: cannot write 'nope/r.html': nope: No such file or directory"},
      {"-o x.png --stats /dev/null", "--stats: cannot write '/dev/null': not a regular file (it would be replaced by one)"},
  };
  for (const auto& [args, message] : refused) {
    const Outcome r = run("bad.nff " + args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(r.err, "vmpray: " + message + "\n") << args;
    EXPECT_EQ(r.out, "") << args;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

// The same for a sweep's output directory: before the scene and the runs.
TEST_F(Checks, ASweepOutputDirectoryIsCheckedBeforeTheRuns) {
  write_bad_scene();
  std::ofstream(dir_ / "file") << "a file\n";
  const Outcome r = run("sweep nodes --scene bad.nff --out file/sweep -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "vmpray sweep: --out: cannot write in 'file/sweep': file: Not a directory (see vmpray sweep --help)\n");
}

TEST(OutputCheck, SaysWhyAPathCannotBeWritten) {
  EXPECT_EQ(app::unwritable_file_reason(fs::temp_directory_path() / "vmpray-fresh.png"), "");
  EXPECT_EQ(app::unwritable_file_reason(fs::temp_directory_path()), "Is a directory");
  EXPECT_EQ(app::unwritable_file_reason("/no/such/dir/x.png"), "/no/such/dir: No such file or directory");
  EXPECT_EQ(app::unwritable_directory_reason(fs::temp_directory_path() / "vmpray-a" / "b"), "");
  EXPECT_EQ(app::unwritable_directory_reason("/dev/null/sweep"), "/dev/null: Not a directory");
}

// `--stats -` writes the JSON on standard output, alone, the report people
// read going to stderr, as a scene "-" is read from standard input; no file
// named "-" is made.
TEST_F(Checks, StatsDashIsStandardOutput) {
  std::ofstream(dir_ / "tiny.nff") << kTinyScene;
  for (const char* mode : {"--single", "--nodes 2"}) {
    const Outcome r = run(std::string("tiny.nff ") + mode + " -o out.ppm --stats -");
    ASSERT_EQ(r.exit_code, 0) << mode << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "-")) << mode;
    ASSERT_FALSE(r.out.empty()) << mode;
    EXPECT_EQ(r.out.front(), '{') << mode << ": " << r.out;
    EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n") << mode << ": " << r.out;
    EXPECT_NE(r.out.find("\"primary\": 64"), std::string::npos) << mode << ": " << r.out;
    EXPECT_NE(r.err.find("rays           "), std::string::npos) << mode << ": " << r.err;
    EXPECT_TRUE(fs::exists(dir_ / "out.ppm")) << mode;
    fs::remove(dir_ / "out.ppm");
  }
}

// A scene that cannot be opened says why in the system's words.
TEST_F(Checks, ASceneThatCannotBeOpenedSaysWhy) {
  fs::create_symlink("loop.nff", dir_ / "loop.nff");
  std::ofstream(dir_ / "file") << "a file\n";
  const std::pair<const char*, const char*> refused[] = {
      {"loop.nff", "vmpray: loop.nff: Too many levels of symbolic links\n"},
      {"file/x.nff", "vmpray: file/x.nff: Not a directory\n"},
      {"no/such.nff", "vmpray: no/such.nff: No such file or directory\n"},
  };
  for (const auto& [scene, message] : refused) {
    const Outcome r = run(std::string(scene) + " -o out.png");
    EXPECT_EQ(r.exit_code, 1) << scene;
    EXPECT_EQ(r.err, message);
  }
}

TEST_F(Checks, AnUnreadableSceneSaysPermissionDenied) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads a file whatever its mode";
  std::ofstream(dir_ / "locked.nff") << kTinyScene;
  fs::permissions(dir_ / "locked.nff", fs::perms::none);
  const Outcome r = run("locked.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "vmpray: locked.nff: cannot open: Permission denied\n");
}

// A scene name that is neither a file nor a built-in is a bad argument, as
// a bad option value is: status 2, as for every other bad argument.
TEST_F(Checks, AnUnknownSceneNameIsABadArgument) {
  for (const char* scene : {"nosuchscene", "tetra:x", "mountain:3"}) {
    const Outcome r = run(std::string(scene) + " -o out.png");
    EXPECT_EQ(r.exit_code, 2) << scene;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind(std::string("vmpray: scene '") + scene + "'", 0), 0u) << r.err;
  }
  const Outcome sweep = run("sweep nodes --scene nosuchscene -q");
  EXPECT_EQ(sweep.exit_code, 2) << sweep.err;
}

// --help and the error give one range for --nodes.
TEST(OptionRanges, HelpAndErrorAgreeOnTheNodes) {
  const std::string help = app::usage_text();
  EXPECT_NE(help.find("at most 4096"), std::string::npos);
  try {
    test::parse({"--nodes", "4097"});
    ADD_FAILURE() << "4097 nodes accepted";
  } catch (const app::UsageError& e) {
    EXPECT_STREQ(e.what(), "--nodes: expected 1..4096, got 4097");
  }
}

TEST(Wording, CountsAndSizes) {
  EXPECT_EQ(app::count_of(1, "node"), "1 node");
  EXPECT_EQ(app::count_of(16, "node"), "16 nodes");
  EXPECT_EQ(app::count_of(2, "pixel computer"), "2 pixel computers");
  EXPECT_EQ(app::size_text(1024), "1.0 KB");
  EXPECT_EQ(app::size_text(768 * 1024), "768.0 KB");
  EXPECT_EQ(app::size_text(1e9 * 1024), "953.7 GB");
}

// The report says "1 node" and a cache of a billion pages in GB.
TEST_F(Checks, TheReportSaysOneNodeAndLargeCachesInTheirUnit) {
  const Outcome r = run("tetra:1 --nodes 1 --cache-pages 1000000000 --width 8 --height 8 -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(": 1 node, 1 pixel computer each"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cache 1000000000 pages (953.7 GB) per node"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("1 nodes"), std::string::npos) << r.out;
}

}  // namespace
