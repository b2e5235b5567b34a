// vmpray network: bad input refused before any run in one line naming the
// option, with nothing written; the files a study writes (the JSON parsed
// here, every packet accounted for); the same files for any --jobs, but for
// the wall time each point took.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

class NetworkCli : public test::ScratchTest {
 protected:
  NetworkCli() : ScratchTest("vmpray_network_cli_") {}
};

TEST_F(NetworkCli, BadInputIsRefusedBeforeAnyRunNamingTheOption) {
  const std::pair<const char*, const char*> refused[] = {
      {"--pattern random", "vmpray network: --pattern: unknown traffic pattern 'random' (known: uniform, transpose, "
                           "bit-complement, bit-reversal, shuffle, tornado, neighbour, hotspot, render)"},
      {"--pattern render --scene nosuch", "vmpray network: scene 'nosuch': unknown built-in scene"},
      {"--pattern render --scene-size 0", "vmpray network: --scene-size: expected 1..1024, got 0"},
      {"--topology mesh:3x4 --pattern bit-reversal",
       "vmpray network: --pattern: bit-reversal traffic needs a power-of-two node count (mesh:3x4 has 12 nodes)"},
      {"--topology hypercube:4 --pattern tornado",
       "vmpray network: --pattern: tornado traffic is not defined on a hypercube: its digits are bits"},
      {"--loads ''", "vmpray network: --loads: empty list"},
      {"--loads 0,0.5", "vmpray network: --loads: expected fractions of the bound above 0 (at most 100), got '0'"},
      {"--loads -1", "vmpray network: --loads: expected fractions of the bound above 0 (at most 100), got '-1'"},
      {"--loads 0.5,0.2", "vmpray network: --loads: expected increasing loads, got 0.2 after 0.500000"},
      {"--topology ring:8,ring:8", "vmpray network: --topology: ring:8 is listed twice"},
      {"--topology star:8", "vmpray network: --topology: "},
      {"--payload 0", "vmpray network: --payload: expected 1..1048576, got 0"},
      {"--hotspot 1", "vmpray network: --hotspot: expected a share above 0 and below 1"},
      {"--links-at 0", "vmpray network: --links-at: expected a load above 0, as a fraction of the bound"},
      {"--cost hop=0,bw=0", "vmpray network: --cost: a network study needs a link cost: hop= or bw= above 0"},
      {"--out /dev/null/out", "vmpray network: --out: cannot write in '/dev/null/out'"},
  };
  for (const auto& [args, message] : refused) {
    const std::string given = args;
    const test::Outcome r = run_vmpray("network " + (given.rfind("--out", 0) == 0 ? given : "--out out " + given));
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind(message, 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << args;
  }
}

TEST_F(NetworkCli, AStudyWritesItsTablesPlotsAndPageWithEveryPacketDelivered) {
  const test::Outcome r = run_vmpray(
      "network --topology hypercube:4,ring:16 --pattern uniform,bit-complement --loads 0.3,0.9,1.5 --out out -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  for (const char* file : {"network.csv", "network.json", "network.svg", "network.html", "network-1-plot.png",
                           "network-4-plot.png"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / file)) << file;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir_ / "out" / "network.json"));
  EXPECT_EQ(j["schema_version"], 1);
  ASSERT_EQ(j["topologies"].size(), 2u);
  EXPECT_EQ(j["topologies"][0]["bisection_links"], 8);
  EXPECT_EQ(j["topologies"][1]["diameter"], 8);
  ASSERT_EQ(j["points"].size(), 2u * 2 * 3);
  for (const auto& p : j["points"]) {
    EXPECT_GT(p["packets"]["created"].get<std::uint64_t>(), 0u);
    EXPECT_EQ(p["packets"]["delivered"], p["packets"]["created"]);
    EXPECT_EQ(p["packets"]["misdelivered"], 0);
    EXPECT_GE(p["latency_s"]["mean"].get<double>(), p["latency_s"]["zero_load"].get<double>() * 0.5);
  }
  // Well below the bound a point is not saturated; at 1.5 times it, every curve is.
  EXPECT_FALSE(j["points"][0]["saturated"].get<bool>());
  EXPECT_TRUE(j["points"][2]["saturated"].get<bool>());
  EXPECT_TRUE(j["points"][11]["saturated"].get<bool>());
  // One link picture a topology, at the load nearest --links-at (0.5: the
  // run at 0.3) under the first pattern, named on the page.
  for (const char* file : {"network-links-1.svg", "network-links-2.svg"})
    EXPECT_EQ(test::read_file(dir_ / "out" / file).rfind("<svg", 0), 0u) << file;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "network-links-3.svg"));
  const std::string page = test::read_file(dir_ / "out" / "network.html");
  for (const char* caption : {"hypercube:4: link traffic, uniform traffic at load 0.30 of the bound",
                              "ring:16: link traffic, uniform traffic at load 0.30 of the bound"})
    EXPECT_NE(page.find(caption), std::string::npos) << caption;
}

// The CSV without its last column (each point's wall time).
std::string without_wall_time(const std::string& csv) {
  std::istringstream lines(csv);
  std::string out;
  for (std::string line; std::getline(lines, line);) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

// The render pattern offers each topology the packets of a render on it:
// all of them, but node 0's messages to its own farmer and collector, which
// cross no link (8 on 16 nodes: a work request, work, a result, two stops,
// the worker's and the server's ends, the server's stop).
TEST_F(NetworkCli, TheRenderPatternOffersEveryPacketOfTheRender) {
  const std::string render = "--topology hypercube:4 --width 16 --height 16 --timing virtual -q";
  ASSERT_EQ(run_vmpray("teapot " + render + " --stats s.json -o t.png").exit_code, 0);
  const nlohmann::json stats = nlohmann::json::parse(test::read_file(dir_ / "s.json"));
  const std::uint64_t packets = stats["machine"]["network"]["packets"].get<std::uint64_t>();
  const std::string study =
      "network --topology hypercube:4,torus:4x4 --pattern render,uniform --scene teapot --scene-size 16 "
      "--loads 0.3,1.5 -q";
  const test::Outcome r = run_vmpray(study + " --jobs 1 --out one");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir_ / "one" / "network.json"));
  EXPECT_EQ(j["render"]["scene"], "teapot");
  EXPECT_EQ(j["render"]["recorded_packets"]["hypercube:4"].get<std::uint64_t>(), packets - 8);
  EXPECT_GT(j["render"]["recorded_packets"]["torus:4x4"].get<std::uint64_t>(), 1000u);
  int render_points = 0;
  for (const auto& p : j["points"]) {
    if (p["pattern"] != "render") continue;
    ++render_points;
    EXPECT_EQ(p["packets"]["delivered"], p["packets"]["created"]) << p;
    EXPECT_EQ(p["packets"]["misdelivered"], 0) << p;
    EXPECT_EQ(p["saturated"], p["load"].get<double>() > 1) << p;
  }
  EXPECT_EQ(render_points, 4);
  ASSERT_EQ(run_vmpray(study + " --jobs 2 --out two").exit_code, 0);
  EXPECT_EQ(without_wall_time(test::read_file(dir_ / "one" / "network.csv")),
            without_wall_time(test::read_file(dir_ / "two" / "network.csv")));
}

TEST_F(NetworkCli, TheTablesAreTheSameOnAnyNumberOfJobs) {
  const std::string study = "network --topology torus:4x4,complete:8 --pattern uniform,hotspot --loads 0.5,1.2 -q";
  ASSERT_EQ(run_vmpray(study + " --jobs 1 --out one").exit_code, 0);
  ASSERT_EQ(run_vmpray(study + " --jobs 3 --out three").exit_code, 0);
  const std::string one = without_wall_time(test::read_file(dir_ / "one" / "network.csv"));
  EXPECT_EQ(one, without_wall_time(test::read_file(dir_ / "three" / "network.csv")));
  EXPECT_EQ(std::count(one.begin(), one.end(), '\n'), 1 + 2 * 2 * 2);
}

}  // namespace
