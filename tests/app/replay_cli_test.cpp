// --replay end to end: the page stands alone (no script or style from
// outside, no URL but data:), its embedded data's totals and the packets it
// recorded add up to the same run's --stats, virtual time replays the same
// page twice, a bound says how many packets it recorded and bounds waits and
// serves with them, and bad uses of
// the options fail in one line before any work.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "app/render/options.hpp"
#include "app/render/ranks.hpp"
#include "tests/support/command_line.hpp"
#include "tests/support/scratch.hpp"

namespace {

using Json = nlohmann::json;
using test::Outcome;
using test::read_file;

class ReplayCli : public test::ScratchTest {
 protected:
  ReplayCli() : ScratchTest("vmpray_replay_") {}

  // The page's embedded data.
  static Json data_of(const std::string& page) {
    const std::string open = "<script type=\"application/json\" id=\"replay-data\">";
    const auto from = page.find(open);
    EXPECT_NE(from, std::string::npos);
    const auto start = from + open.size();
    const auto end = page.find("</script>", start);
    std::string text = page.substr(start, end - start);
    return Json::parse(std::regex_replace(text, std::regex("<\\\\/"), "</"));
  }
};

constexpr const char* kRun = "teapot:2 --width 48 --height 40 --topology torus:3x2 --threads 2 -o out.png";

std::uint64_t sum(const Json& array) {
  std::uint64_t s = 0;
  for (const Json& v : array) s += v.get<std::uint64_t>();
  return s;
}

void expect_totals_match(const Json& data, const Json& machine) {
  const Json& totals = data.at("totals");
  EXPECT_EQ(totals.at("packets"), machine.at("network").at("packets"));
  EXPECT_NEAR(totals.at("hops").get<double>(),
              machine.at("network").at("packets").get<double>() * machine.at("network").at("mean_hops").get<double>(),
              1e-6 * totals.at("hops").get<double>() + 1e-9);
  EXPECT_EQ(totals.at("misses"), machine.at("svm").at("misses"));
  std::uint64_t pixels = 0;
  for (const Json& n : machine.at("per_node")) pixels += n.at("pixels").get<std::uint64_t>();
  EXPECT_EQ(totals.at("pixels").get<std::uint64_t>(), pixels);
  // What the page counts up to: recorded plus only counted.
  const Json& p = data.at("packets");
  EXPECT_EQ(p.at("kind").size() + data.at("unrecorded").at("packets").get<std::uint64_t>(),
            totals.at("packets").get<std::uint64_t>());
  EXPECT_EQ(sum(p.at("hops")) + data.at("unrecorded").at("hops").get<std::uint64_t>(),
            totals.at("hops").get<std::uint64_t>());
  EXPECT_EQ(data.at("fetches").at("start").size() + data.at("unrecorded").at("fetches").get<std::uint64_t>(),
            totals.at("misses").get<std::uint64_t>());
  EXPECT_EQ(sum(data.at("tiles").at("count")), pixels);
  EXPECT_EQ(sum(data.at("hits").at("hits")), machine.at("svm").at("local_hits").get<std::uint64_t>() +
                                                 machine.at("svm").at("cache_hits").get<std::uint64_t>());
  // Each packet: hops + 1 route nodes, two times a node.
  EXPECT_EQ(p.at("route").size(), sum(p.at("hops")) + p.at("kind").size());
  EXPECT_EQ(p.at("times").size(), 2 * p.at("route").size());
}

TEST_F(ReplayCli, ThePageStandsAloneAndItsTotalsAreTheStats) {
  const Outcome r = run_vmpray(std::string(kRun) + " --replay run.html --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = read_file(dir_ / "run.html");
  EXPECT_EQ(page.find("<script src"), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  // No URL to fetch; the SVG's namespaces are names, not addresses.
  EXPECT_FALSE(std::regex_search(page, std::regex("(src|href)=\"(https?:|//)")));
  EXPECT_NE(page.find("window.vmprayReplay"), std::string::npos);
  EXPECT_NE(page.find("<svg"), std::string::npos);
  const Json data = data_of(page);
  const Json machine = Json::parse(read_file(dir_ / "s.json")).at("machine");
  expect_totals_match(data, machine);
  EXPECT_EQ(data.at("timing"), "real");
  EXPECT_EQ(data.at("unrecorded").at("packets"), 0);
  EXPECT_EQ(data.at("places").size(), 6u);
  EXPECT_EQ(data.at("image").at("width"), 48);
}

TEST_F(ReplayCli, VirtualTimeWritesTheSamePageEveryTime) {
  const std::string run = std::string(kRun) + " --timing virtual --replay ";
  ASSERT_EQ(run_vmpray(run + "a.html --stats s.json").exit_code, 0);
  ASSERT_EQ(run_vmpray(run + "b.html").exit_code, 0);
  const Json a = data_of(read_file(dir_ / "a.html")), b = data_of(read_file(dir_ / "b.html"));
  EXPECT_EQ(a.at("timing"), "virtual");
  EXPECT_EQ(a.at("packets"), b.at("packets"));
  EXPECT_EQ(a.at("tiles"), b.at("tiles"));
  expect_totals_match(a, Json::parse(read_file(dir_ / "s.json")).at("machine"));
}

TEST_F(ReplayCli, ABoundRecordsThatManyPacketsAndCountsTheRest) {
  const Outcome r = run_vmpray(std::string(kRun) + " --replay run.html --replay-packets 40 --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json data = data_of(read_file(dir_ / "run.html"));
  EXPECT_EQ(data.at("packets").at("kind").size(), 40u);
  EXPECT_EQ(data.at("maxPackets"), 40);
  EXPECT_GT(data.at("unrecorded").at("packets").get<int>(), 0);
  expect_totals_match(data, Json::parse(read_file(dir_ / "s.json")).at("machine"));
}

// The bound holds for everything that grows with the run: with the cache
// too small to hold anything, waits for pages and serves outnumber the
// packet budget many times, and the page stays the size of a short run.
TEST_F(ReplayCli, TheBoundCoversWaitsAndServesAndThePageFollowsIt) {
  const std::string run = std::string(kRun) + " --cache-pages 1 --stats s.json --replay ";
  ASSERT_EQ(run_vmpray(run + "all.html").exit_code, 0);
  const Outcome r = run_vmpray(run + "few.html --replay-packets 20");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json all = data_of(read_file(dir_ / "all.html")), few = data_of(read_file(dir_ / "few.html"));
  const Json machine = Json::parse(read_file(dir_ / "s.json")).at("machine");
  expect_totals_match(few, machine);
  const std::uint64_t misses = machine.at("svm").at("misses").get<std::uint64_t>();
  ASSERT_EQ(all.at("fetches").at("start").size(), all.at("totals").at("misses").get<std::uint64_t>());
  EXPECT_GT(misses, 400u);
  // 20 packets, and the waits and serves of at most the 6 nodes' one request each in flight.
  EXPECT_LE(few.at("fetches").at("start").size(), 20u + 2 * 6);
  EXPECT_LE(few.at("serves").at("start").size(), 20u + 2 * 6);
  EXPECT_GT(few.at("unrecorded").at("serves").get<std::uint64_t>(), 0u);
  EXPECT_LT(few.at("window"), few.at("end"));
  EXPECT_LT(4 * std::filesystem::file_size(dir_ / "few.html") / 3, std::filesystem::file_size(dir_ / "all.html"));
}

TEST_F(ReplayCli, BadUsesFailInOneLineBeforeAnyWork) {
  for (const std::string bad : {"--replay run.svg", "--replay-packets 10", "--replay run.html --replay-packets -1",
                                "--replay run.html --replay-packets 99999999", "--replay run.html --report run.html"}) {
    const Outcome r = run_vmpray(std::string(kRun) + " " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("--replay"), std::string::npos) << bad << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "run.html")) << bad;
  }
  const Outcome single = run_vmpray("teapot:2 --width 16 --height 16 --single --replay run.html");
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_NE(single.err.find("--replay: an option of the machine"), std::string::npos) << single.err;
}

TEST(ReplayOptions, ReplayAsksTheMachineToRecordWithItsBound) {
  const app::Options o = test::parse_words("teapot --replay r.html --replay-packets 123");
  EXPECT_TRUE(o.machine.observe.record);
  EXPECT_EQ(o.machine.observe.record_packets, 123u);
  EXPECT_FALSE(test::parse_words("teapot").machine.observe.record);
  EXPECT_EQ(test::parse_words("teapot --replay r.html").machine.observe.record_packets, 100000u);
}

TEST(ReplayOptions, IsTakenOverSeveralRanks) {
  const app::Options o = test::parse_words("teapot --replay r.html");
  EXPECT_NO_THROW(app::check_rank_options(o, 1));
  EXPECT_NO_THROW(app::check_rank_options(o, 2));
}

TEST(ReplayOptions, HelpNamesTheOptions) {
  const std::string help = app::usage_text();
  EXPECT_NE(help.find("--replay "), std::string::npos);
  EXPECT_NE(help.find("--replay-packets"), std::string::npos);
  EXPECT_NE(help.find("over mpirun too"), std::string::npos);
}

}  // namespace
