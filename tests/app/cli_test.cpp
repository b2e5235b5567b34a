// The vmpray executable end to end: exit codes, one-line errors, no partial
// output on failure, image and JSON on success.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

using test::Outcome;

class Cli : public test::ScratchTest {
 protected:
  Cli() : ScratchTest("vmpray_cli_") {}
  Outcome run(const std::string& args) { return run_vmpray(args); }
  std::size_t lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }
};

TEST_F(Cli, MissingSceneFileIsARuntimeErrorWithNoOutput) {
  const Outcome r = run("no/such/scene.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("no/such/scene.nff"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, UnknownBuiltinIsARuntimeError) {
  const Outcome r = run("nosuchscene -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, BadOptionValueIsAUsageError) {
  for (const char* args : {"--page-size 1000 -o out.png", "--accel octree -o out.png",
                           "-o out.bmp", "--bogus -o out.png"}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
  EXPECT_FALSE(fs::exists(dir_ / "out.bmp"));
}

TEST_F(Cli, MalformedSceneNamesFileAndLine) {
  std::ofstream(dir_ / "bad.nff") << "v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\n"
                                     "hither 1\nresolution 8 8\ns 0 0 zero 1\n";
  const Outcome r = run("bad.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("bad.nff:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, RendersImageAndJsonStats) {
  const Outcome r = run("tetra:1 --width 24 --height 16 -o out.ppm --stats s.json --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_EQ(fs::file_size(dir_ / "out.ppm"), std::string("P6\n24 16\n255\n").size() + 24 * 16 * 3);
  std::ifstream in(dir_ / "s.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("\"primary\": 384"), std::string::npos) << ss.str();
  EXPECT_NE(ss.str().find("\"page_size\": 1024"), std::string::npos);
  EXPECT_NE(ss.str().find("\"shadow_rays\": \"facing\""), std::string::npos);
}

TEST_F(Cli, ReportNamesTheShadowRayPolicyInTextAndJson) {
  const Outcome r = run_vmpray("tetra:1 --single --width 16 --height 16 -o out.ppm --shadow-rays all --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(shadow rays to every light)"), std::string::npos) << r.out;
  EXPECT_NE(test::read_file(dir_ / "s.json").find("\"shadow_rays\": \"all\""), std::string::npos);
}

}  // namespace
