// What vmpray checks before its work and how it says so: every output path
// before the scene is read, `--stats -` as standard output, the system's
// reason for a file it cannot open, one wording, one range and one exit
// status for each kind of bad argument; tessellations and images too large
// for the memory refused by what asked for them; warnings for a scene that
// would render as nothing and a mesh that would be a line; JSON that is
// UTF-8 whatever the file names; a scene file parsed as a stream.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "app/experiments/output_check.hpp"
#include "app/render/run_report.hpp"
#include "app/render/wording.hpp"
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

namespace {

// One range for --tessellate, in the help and the check, and the same as
// the tessellator's own.
TEST(OptionRanges, TessellateHasOneRange) {
  EXPECT_NE(app::usage_text().find("this resolution, 1..64"), std::string::npos) << app::usage_text();
  EXPECT_EQ(test::parse({"--tessellate", "64"}).tessellate, 64);
  try {
    test::parse({"--tessellate", "65"});
    ADD_FAILURE() << "65 accepted";
  } catch (const app::UsageError& e) {
    EXPECT_STREQ(e.what(), "--tessellate: expected 1..64, got 65");
  }
}

// A tessellation whose scene cannot fit in the memory is refused before it
// is made, by the option or the scene spec that asked for it, instead of
// running until an allocation fails; one that fits still renders.
TEST_F(Checks, ATessellationTooLargeForTheMemoryIsRefusedBeforeItIsMade) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 2 GB of address space";
#endif
  const auto limited = [&](const std::string& args) { return run_vmpray(args, "stdout.txt", "ulimit -v 2000000"); };
  const std::pair<const char*, const char*> refused[] = {
      {"balls:4 --tessellate 64 --width 8 --height 8 -o out.png",
       "vmpray: --tessellate 64: the scene tessellated becomes 362790913 objects, needing about 145.1 GB, more than "
       "the 2.0 GB this process may map (ulimit -v)\n"},
      {"balls:4:t64 --width 8 --height 8 -o out.png",
       "vmpray: scene 'balls:4:t64': the scene tessellated becomes 362790913 objects"},
  };
  for (const auto& [args, message] : refused) {
    const Outcome r = limited(args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind(message, 0), 0u) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out.png"));
  }
  const Outcome fits = limited("balls:1 --tessellate 8 --width 8 --height 8 -q -o out.png");
  EXPECT_EQ(fits.exit_code, 0) << fits.err;
}

// A scene whose loading or database runs out of the memory this process may
// map (ulimit -v), which no check foresees, ends on one line naming the
// step and the limit, with no output.
TEST_F(Checks, ASceneTooLargeForTheMemoryNamesTheStepThatRanOut) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in these address spaces";
#endif
  const std::pair<const char*, const char*> cases[] = {
      {"ulimit -v 120000", "vmpray: out of memory loading the scene: it needs more than the 123 MB this process may "
                           "map (ulimit -v)\n"},
      {"ulimit -v 250000", "vmpray: out of memory building the database: it needs more than the 256 MB this process "
                           "may map (ulimit -v)\n"},
  };
  for (const auto& [limit, message] : cases) {
    for (const char* machine : {"--single", "--nodes 4"}) {
      const Outcome r = run_vmpray(std::string("tetra10 ") + machine + " --width 8 --height 8 -o out.png",
                                   "stdout.txt", limit);
      EXPECT_EQ(r.exit_code, 1) << limit << " " << machine << ": " << r.err;
      EXPECT_EQ(r.err, message) << limit << " " << machine;
      EXPECT_FALSE(fs::exists(dir_ / "out.png"));
    }
  }
}

// An image too large, at the size the scene's "resolution" set, is blamed
// on that line of the scene, not on options that were not given.
TEST_F(Checks, AnImageTooLargeFromTheSceneNamesItsLine) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 2 GB of address space";
#endif
  std::ofstream(dir_ / "big.nff") << "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.1\n"
                                     "resolution 16384 16384\nl 0 0 5\ns 0 0 0 1\n";
  const auto limited = [&](const std::string& args) { return run_vmpray(args, "stdout.txt", "ulimit -v 2000000"); };
  const Outcome from_scene = limited("big.nff -o out.png");
  EXPECT_EQ(from_scene.exit_code, 2);
  EXPECT_EQ(from_scene.err,
            "vmpray: big.nff:7: a 16384x16384 image needs about 8.1 GB, more than the 2.0 GB this process may map "
            "(ulimit -v); --width and --height render it smaller\n");
  const Outcome from_options = limited("big.nff --width 16384 -o out.png");
  EXPECT_EQ(from_options.exit_code, 2);
  EXPECT_EQ(from_options.err.rfind("vmpray: --width/--height: a 16384x16384 image", 0), 0u) << from_options.err;
}

// A scene that would render as nothing says so on stderr, and renders.
TEST_F(Checks, ASceneWithNoLightsOrNoObjectsIsWarnedOf) {
  std::ofstream(dir_ / "dark.nff") << "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 0.1 resolution 8 8\ns 0 0 0 1\n";
  std::ofstream(dir_ / "empty.nff") << "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 0.1 resolution 8 8\nl 0 0 5\n";
  const std::pair<const char*, const char*> warned[] = {
      {"dark.nff", "vmpray: warning: dark.nff has no lights ('l'): every surface it shows renders black\n"},
      {"empty.nff", "vmpray: warning: empty.nff has no objects: the image is its background colour alone\n"},
  };
  for (const auto& [scene, warning] : warned) {
    const Outcome r = run(std::string(scene) + " -q --nodes 2 -o out.png");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, warning);
    EXPECT_TRUE(fs::exists(dir_ / "out.png"));
    fs::remove(dir_ / "out.png");
  }
  std::ofstream(dir_ / "lit.nff") << kTinyScene;
  EXPECT_EQ(run("lit.nff -q --nodes 2 -o out.png").err, "");
}

// A bare mesh or torus of a count with no factors would be a line: refused
// with the shape to give instead; any other count gets its squarest shape,
// which the report names.
TEST_F(Checks, AMeshThatWouldBeALineIsRefusedAndTheShapeIsReported) {
  for (const char* kind : {"mesh", "torus"}) {
    const Outcome r = run(std::string("tetra:1 --topology ") + kind + " --nodes 17 -o out.png");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, std::string("vmpray: --topology ") + kind + " --nodes 17: the only " + kind +
                         " of 17 nodes is 17x1, a line; give that shape (" + kind +
                         ":17x1), a ring, or a count with factors such as 16 or 18 (see vmpray --help)\n");
  }
  EXPECT_NO_THROW(test::parse({"--topology", "mesh:17x1"}));
  EXPECT_NO_THROW(test::parse({"--topology", "mesh", "--nodes", "3"}));
  const Outcome r = run("tetra:1 --topology mesh --nodes 8 --width 8 --height 8 -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("machine        mesh:4x2: 8 nodes"), std::string::npos) << r.out;
}

}  // namespace

namespace {

// Whether `s` is UTF-8 as RFC 3629 has it, decoded code point by code point.
bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const int extra = b < 0x80 ? 0 : (b >> 5) == 6 ? 1 : (b >> 4) == 14 ? 2 : (b >> 3) == 30 ? 3 : -1;
    if (extra < 0 || i + extra >= s.size()) return false;
    std::uint32_t code = extra == 0 ? b : b & (0x3f >> extra);
    for (int k = 1; k <= extra; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      if ((c >> 6) != 2) return false;
      code = code << 6 | (c & 0x3f);
    }
    const std::uint32_t least[] = {0, 0x80, 0x800, 0x10000};
    if (code < least[extra] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return false;
    i += extra + 1;
  }
  return true;
}

TEST(JsonText, KeepsUtf8AndReplacesWhatIsNot) {
  const auto json_string = [](const std::string& s) { return app::dump_json(app::Json(s)); };
  const std::string fffd = "\xef\xbf\xbd";  // U+FFFD, the replacement character
  EXPECT_EQ(json_string("caf\xc3\xa9 \xe2\x82\xac"), "\"caf\xc3\xa9 \xe2\x82\xac\"");
  EXPECT_EQ(json_string("lat\xe9.nff"), "\"lat" + fffd + ".nff\"");
  EXPECT_EQ(json_string("\xc0\xaf"), "\"" + fffd + fffd + "\"") << "an overlong '/'";
  EXPECT_EQ(json_string("\xed\xa0\x80"), "\"" + fffd + fffd + fffd + "\"") << "a surrogate";
  EXPECT_EQ(json_string("\xe2\x82"), "\"" + fffd + "\"") << "cut short";
  EXPECT_EQ(json_string("a\"b\\\n\x01"), "\"a\\\"b\\\\\\n\\u0001\"");
}

// A scene whose file name is not UTF-8 (Latin-1 here) still gives a valid
// UTF-8 JSON report.
TEST_F(Checks, StatsJsonIsUtf8WhateverTheFileName) {
  const std::string name = "lat\xe9.nff";
  std::ofstream(dir_ / name) << kTinyScene;
  const Outcome r = run("'" + name + "' --nodes 2 -q -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json = test::read_file(dir_ / "s.json");
  EXPECT_TRUE(valid_utf8(json));
  EXPECT_NE(json.find("\"scene\": \"lat\xef\xbf\xbd.nff\""), std::string::npos) << json;
}

}  // namespace

namespace {

// A gzip of 150 MB of blanks around a one-sphere scene loads in an address
// space of 100 MB (ulimit -v): the scene is parsed as it is inflated, so
// memory follows the scene and not the size of the file.
TEST_F(Checks, ASceneFileLargerThanTheMemoryLoadsAsAStream) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 100 MB of address space";
#endif
  const std::string make = "cd '" + dir_.string() +
                           "' && { printf 'v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 0.1 resolution 8 8\\nl 0 0 5\\n';"
                           " yes '                                                               ' | head -c 150000000;"
                           " printf 's 0 0 0 1\\n'; } | gzip -1 > blank.nff.gz";
  ASSERT_EQ(std::system(make.c_str()), 0);
  ASSERT_LT(fs::file_size(dir_ / "blank.nff.gz"), 10'000'000u);
  const Outcome r = run_vmpray("blank.nff.gz --single --stats s.json -q -o out.png", "stdout.txt", "ulimit -v 100000");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(test::read_file(dir_ / "s.json").find("\"objects\": 1,"), std::string::npos);
}

}  // namespace
