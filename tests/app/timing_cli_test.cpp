// `vmpray --timing virtual` end to end: the predicted time and statistics do
// not depend on --threads, and bad timing options fail with one line naming
// the option (or the profile file and line).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

class TimingCli : public test::ScratchTest {
 protected:
  TimingCli() : ScratchTest("vmpray_timing_") {}

  // Exit code; stderr in err_.
  int run(const std::string& args) {
    const test::Outcome r = run_vmpray(args);
    err_ = r.err;
    return r.exit_code;
  }

  static std::string read(const fs::path& p) { return test::read_file(p); }

  // The JSON fields that must not depend on the thread count.
  std::string deterministic_fields(const std::string& json) {
    std::string out;
    const std::regex field(R"re("(predicted_seconds|misses|pages_served|rays|items|parallel_seconds|seconds)": ([0-9.e+-]+))re");
    for (auto it = std::sregex_iterator(json.begin(), json.end(), field); it != std::sregex_iterator(); ++it)
      out += (*it)[1].str() + "=" + (*it)[2].str() + ";";
    return out;
  }

  std::string err_;
};

TEST_F(TimingCli, PredictionIsTheSameOnOneAndTwoThreads) {
  const std::string common = "teapot:2 --width 16 --height 16 --nodes 8 --cache-pages 4 --timing virtual -q";
  ASSERT_EQ(run(common + " --threads 1 --stats one.json -o one.png"), 0) << err_;
  ASSERT_EQ(run(common + " --threads 2 --stats two.json -o two.png"), 0) << err_;
  const std::string one = deterministic_fields(read(dir_ / "one.json"));
  EXPECT_NE(one.find("predicted_seconds="), std::string::npos) << one;
  EXPECT_EQ(one, deterministic_fields(read(dir_ / "two.json")));
}

TEST_F(TimingCli, BadTimingOptionsNameTheOptionOnOneLine) {
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --timing sideways"), 2);
  EXPECT_NE(err_.find("--timing"), std::string::npos) << err_;
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --timing virtual --cost box=quick"), 2);
  EXPECT_NE(err_.find("--cost"), std::string::npos) << err_;
  std::ofstream(dir_ / "machine.txt") << "profile = ipsc2\nhop: 3us\n";
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --timing virtual --profile machine.txt"), 2);
  EXPECT_NE(err_.find("machine.txt:2:"), std::string::npos) << err_;
  EXPECT_EQ(std::count(err_.begin(), err_.end(), '\n'), 1) << err_;
}

// A model changes nothing in a wall-time run, so asking for one there is a mistake.
TEST_F(TimingCli, AModelWithoutVirtualTimingIsAnError) {
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --cost box=1us"), 2);
  EXPECT_NE(err_.find("--cost: a model for --timing virtual"), std::string::npos) << err_;
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --timing real --profile native"), 2);
  EXPECT_NE(err_.find("--profile: a model for --timing virtual"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(dir_ / "teapot-2.png"));
}

TEST_F(TimingCli, ShadowRaysToAllLightsCountMoreRaysForTheSameImage) {
  const std::string common = "teapot:2 --width 24 --height 24 --nodes 4 --timing virtual -q";
  ASSERT_EQ(run(common + " --stats facing.json -o facing.ppm"), 0) << err_;
  ASSERT_EQ(run(common + " --shadow-rays all --stats all.json -o all.ppm"), 0) << err_;
  EXPECT_EQ(read(dir_ / "all.ppm"), read(dir_ / "facing.ppm"));
  const std::regex shadow(R"re("shadow": ([0-9]+))re"), predicted(R"re("predicted_seconds": ([0-9.e+-]+))re");
  std::smatch a, f;
  const std::string all = read(dir_ / "all.json"), facing = read(dir_ / "facing.json");
  ASSERT_TRUE(std::regex_search(all, a, shadow) && std::regex_search(facing, f, shadow)) << all;
  EXPECT_GT(std::stoull(a[1].str()), std::stoull(f[1].str()));
  ASSERT_TRUE(std::regex_search(all, a, predicted) && std::regex_search(facing, f, predicted)) << all;
  EXPECT_GT(std::stod(a[1].str()), std::stod(f[1].str()));  // more rays, more work
}

TEST_F(TimingCli, BadShadowRaysNamesTheOptionOnOneLine) {
  EXPECT_EQ(run("teapot:2 --width 8 --height 8 --shadow-rays some"), 2);
  EXPECT_NE(err_.find("--shadow-rays: expected facing or all, got 'some'"), std::string::npos) << err_;
  EXPECT_EQ(std::count(err_.begin(), err_.end(), '\n'), 1) << err_;
}

}  // namespace
