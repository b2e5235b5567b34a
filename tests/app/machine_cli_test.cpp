// The machine mode of vmpray: option parsing, and the binary end to end —
// images identical to the single-process renderer (on one thread or
// several), the machine fields of the JSON report, route traces,
// and one-line errors with no output file for each kind of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/render/options.hpp"
#include "tests/support/command_line.hpp"
#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

// The --stats documents, read with nlohmann-json; at() throws on a missing field.
using Json = nlohmann::json;

using test::Outcome;
using test::read_file;

class MachineCli : public test::ScratchTest {
 protected:
  MachineCli() : ScratchTest("vmpray_mcli_") {}
  Outcome run(const std::string& args) { return run_vmpray(args); }
  static std::size_t lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }
};

constexpr const char* kSmall = "tetra:3 --width 32 --height 32 --threads 2";

// A cache larger than the pages a node does not own is capped there; the
// report says so rather than claim the size asked for.
TEST_F(MachineCli, ACacheLargerThanTheRemotePagesIsReportedAsCapped) {
  const Outcome r = run(std::string(kSmall) + " --cache-pages 100000 -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json m = Json::parse(read_file(dir_ / "s.json")).at("machine");
  double largest = 0;
  for (const Json& n : m.at("per_node")) largest = std::max(largest, n.at("cache_pages").get<double>());
  EXPECT_EQ(m.at("cache_pages").get<double>(), 100000);
  EXPECT_EQ(m.at("cache_pages_largest_in_use").get<double>(), largest);
  EXPECT_LE(largest, m.at("database_pages").get<double>());
  EXPECT_NE(r.out.find("holding every remote page (at most " + std::to_string(int(largest)) + ")"), std::string::npos)
      << r.out;
}

// More threads than nodes are lowered to one a node, and the run says so on
// stderr; as many threads as nodes, or fewer, says nothing.
TEST_F(MachineCli, ThreadsAboveTheNodesAreLoweredWithANote) {
  const Outcome r = run("tetra:3 --width 16 --height 16 --topology ring:4 --threads 8 -q -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "vmpray: --threads 8 lowered to 4: no more threads than nodes\n");
  const Outcome fits = run("tetra:3 --width 16 --height 16 --topology ring:4 --threads 4 -q -o out.png");
  ASSERT_EQ(fits.exit_code, 0) << fits.err;
  EXPECT_EQ(fits.err, "");
}

// Under the SPD procedure the machine farms out corner samples, and the
// report counts them as such.
TEST_F(MachineCli, SpdProcedureReportsSamplesNotPixels) {
  const Outcome r = run(std::string(kSmall) + " --spd-procedure -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("distinct pages per sample"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("per node       samples imbalance"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("pixels"), std::string::npos) << r.out;
  const Json j = Json::parse(read_file(dir_ / "s.json"));
  double samples = 0;
  for (const Json& n : j.at("machine").at("per_node")) samples += n.at("pixels").get<double>();
  EXPECT_EQ(samples, 33 * 33);
}

TEST_F(MachineCli, DefaultMachineWritesImageAndJsonWithMachineFields) {
  const Outcome r = run(std::string(kSmall) + " -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.png"));
  const Json j = Json::parse(read_file(dir_ / "s.json"));
  // Which program wrote it, how it was called, and the layout's version.
  EXPECT_EQ(j.at("schema_version").get<double>(), 2);
  EXPECT_FALSE(j.at("vmpray_version").get<std::string>().empty());
  ASSERT_GE(j.at("command_line").size(), 4u);
  EXPECT_EQ(j.at("command_line")[1].get<std::string>(), "tetra:3");
  EXPECT_EQ(j.at("command_line").back().get<std::string>(), "s.json");
  const Json& m = j.at("machine");
  EXPECT_EQ(m.at("topology").get<std::string>(), "hypercube:4");
  EXPECT_EQ(m.at("nodes").get<double>(), 16);
  ASSERT_EQ(m.at("per_node").size(), 16u);
  const Json& svm = m.at("svm");
  EXPECT_GT(svm.at("accesses").get<double>(), 0);
  // The share of accesses that went to another node, coalesced misses
  // included; some must, as each node owns a sixteenth of the pages.
  EXPECT_DOUBLE_EQ(svm.at("miss_ratio").get<double>(),
                   (svm.at("misses").get<double>() + svm.at("coalesced").get<double>()) /
                       svm.at("accesses").get<double>());
  EXPECT_GT(svm.at("miss_ratio").get<double>(), 0);
  EXPECT_LE(svm.at("miss_ratio").get<double>(), 1);
  double misses = 0, pixels = 0, rays = 0;
  for (const Json& n : m.at("per_node")) {
    misses += n.at("svm").at("misses").get<double>();
    pixels += n.at("pixels").get<double>();
    rays += n.at("rays").get<double>();
  }
  EXPECT_EQ(misses, m.at("page_communications").get<double>());  // every request answered once
  EXPECT_EQ(pixels, 32 * 32);
  EXPECT_EQ(rays, j.at("rays").at("total").get<double>());
  EXPECT_GE(m.at("imbalance").at("pixels").get<double>(), 1.0);
  EXPECT_GT(m.at("network").at("packets").get<double>(), 0);
  EXPECT_TRUE(m.at("serial").is_null());
  EXPECT_EQ(m.at("schedule").get<std::string>(), "affinity");
  EXPECT_EQ(m.at("pixel_order").get<std::string>(), "hilbert");
  EXPECT_EQ(m.at("grain").get<double>(), 64);
  ASSERT_EQ(m.at("host_threads").size(), 2u);
  for (const Json& t : m.at("host_threads")) {
    EXPECT_GT(t.at("seconds").get<double>(), 0);
    EXPECT_LE(t.at("seconds").get<double>(), m.at("wall_seconds").get<double>());
    EXPECT_GE(t.at("idle_seconds").get<double>(), 0);
    EXPECT_LE(t.at("idle_seconds").get<double>(), t.at("seconds").get<double>());
    const double parts = t.at("running_seconds").get<double>() + t.at("spinning_seconds").get<double>() +
                         t.at("sleeping_seconds").get<double>();
    EXPECT_NEAR(parts, t.at("seconds").get<double>(), 1e-6 + 1e-6 * t.at("seconds").get<double>());
    EXPECT_GT(t.at("running_seconds").get<double>(), 0);  // every thread holds nodes that trace
    EXPECT_GT(t.at("cpu_seconds").get<double>(), 0);
  }
  // The links between the two threads' subcubes go through the relays:
  // every packet one relay put in a ring, the other took out.
  EXPECT_GT(m.at("relayed_links").get<double>(), 0);
  ASSERT_EQ(m.at("relays").size(), 2u);
  double relay_sent = 0, relay_received = 0;
  for (std::size_t t = 0; t < 2; ++t) {
    const Json& relay = m.at("relays")[t];
    relay_sent += relay.at("packets_sent").get<double>();
    relay_received += relay.at("packets_received").get<double>();
    // Routers put in some of them themselves (the default), never more than were put in.
    EXPECT_LE(relay.at("sent_in_place").get<double>(), relay.at("packets_sent").get<double>());
    // A relay wakes once as it starts, then only to a signal from the other thread's relay.
    EXPECT_GE(relay.at("wakes").get<double>(), 1);
    EXPECT_LE(relay.at("wakes").get<double>(), 1 + m.at("relays")[1 - t].at("signals").get<double>());
    // A thread is woken from sleep only for a process woken there or a relay's signal.
    const Json& use = m.at("host_threads")[t];
    EXPECT_LE(use.at("sleepers_woken").get<double>(),
              use.at("remote_wakes").get<double>() + relay.at("signals").get<double>());
  }
  EXPECT_GT(relay_sent, 0);
  EXPECT_EQ(relay_sent, relay_received);
  EXPECT_NE(r.out.find("between threads "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("% of thread time"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("thread 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("running "), std::string::npos) << r.out;
}

// In virtual time the cost model is an object with every constant, the
// iPSC/2's as the paper gives them, and no host-thread accounting.
TEST_F(MachineCli, VirtualTimeStatsCarryTheCostModelAsAnObject) {
  const Outcome r = run(std::string(kSmall) + " --timing virtual -q -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json m = Json::parse(read_file(dir_ / "s.json")).at("machine");
  const Json& model = m.at("cost_model");
  ASSERT_TRUE(model.is_object()) << model;
  EXPECT_EQ(model.at("name").get<std::string>(), "ipsc2");
  EXPECT_DOUBLE_EQ(model.at("msg").get<double>(), 175e-6);
  for (const char* constant : {"unit", "box", "prim", "shade", "page", "serve", "hop", "bandwidth"})
    EXPECT_GT(model.at(constant).get<double>(), 0) << constant;
  EXPECT_NE(model.at("description").get<std::string>().find("ipsc2"), std::string::npos);
  EXPECT_GT(m.at("predicted_seconds").get<double>(), 0);
  EXPECT_FALSE(m.contains("host_threads"));
}

TEST_F(MachineCli, AffinityScheduleIsReportedWithItsSteals) {
  const Outcome r = run(std::string(kSmall) + " --schedule affinity --grain 4 -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("affinity schedule (grain 4, "), std::string::npos) << r.out;
  const Json j = Json::parse(read_file(dir_ / "s.json"));
  const Json& m = j.at("machine");
  EXPECT_EQ(m.at("schedule").get<std::string>(), "affinity");
  EXPECT_EQ(m.at("grain").get<double>(), 4);
  // Nodes whose share is background finish early and take from the others.
  EXPECT_GT(m.at("steals").get<double>(), 0);
}

TEST_F(MachineCli, ThePapersFarmingIsReported) {
  const Outcome r = run(std::string(kSmall) + " --schedule dynamic --pixel-order scanline -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("dynamic schedule (grain 64) in scanline order"), std::string::npos) << r.out;
  const Json j = Json::parse(read_file(dir_ / "s.json"));
  EXPECT_EQ(j.at("machine").at("schedule").get<std::string>(), "dynamic");
  EXPECT_EQ(j.at("machine").at("pixel_order").get<std::string>(), "scanline");
  EXPECT_EQ(j.at("machine").at("steals").get<double>(), 0);
}

TEST_F(MachineCli, BvhLayoutIsReported) {
  for (const char* layout : {"treelet", "depth-first"}) {
    const Outcome r = run(std::string(kSmall) + " --bvh-layout " + layout + " -o out.png --stats s.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(std::string("(bvh, ") + layout + " layout, built in"), std::string::npos) << r.out;
    const Json j = Json::parse(read_file(dir_ / "s.json"));
    EXPECT_EQ(j.at("database").at("bvh_layout").get<std::string>(), layout);
  }
}

TEST_F(MachineCli, EveryMachineMakesTheSingleProcessImage) {
  const std::string scene = "teapot:2 --width 24 --height 20 -q";
  ASSERT_EQ(run(scene + " --single -o single.ppm").exit_code, 0);
  const std::string single = read_file(dir_ / "single.ppm");
  ASSERT_FALSE(single.empty());
  const std::vector<std::string> machines{
      "",
      "--topology mesh:3x3 --cache-pages 1 --schedule static --distribution block",
      "--topology ring --nodes 5 --workers-per-node 2 --page-size 256 --schedule dynamic",
      "--topology torus:4x2 --cache-kb 2 --grain 1 --prefetch 0 --pixel-order scanline",
      "--topology hypercube:3 --grain 3 --prefetch 3 --schedule dynamic --pixel-order scanline",
      "--topology ring:6 --grain 2 --workers-per-node 2 --pixel-order scanline",
      "--topology mesh:2x3 --schedule static --cache-pages 2",
      "--topology hypercube:2 --grain 5 --workers-per-node 3",
      "--topology complete:1",
      "--topology hypercube:3 --bvh-layout depth-first --cache-pages 3",
  };
  for (const std::string& m : machines) {
    const Outcome r = run(scene + " --threads 2 " + m + " -o machine.ppm");
    ASSERT_EQ(r.exit_code, 0) << m << ": " << r.err;
    EXPECT_TRUE(read_file(dir_ / "machine.ppm") == single) << m;
  }
}

// The single-process renderer on several threads makes the image and the
// counts of one thread, and says how many threads traced.
TEST_F(MachineCli, TheSingleProcessRendererOnThreadsMakesTheSameImageAndCounts) {
  const std::string scene = "teapot:2 --width 24 --height 20 -q --single";
  ASSERT_EQ(run(scene + " --threads 1 -o one.ppm --stats one.json").exit_code, 0);
  const Json one = Json::parse(read_file(dir_ / "one.json"));
  EXPECT_EQ(one.at("render_threads"), 1);
  for (const char* threads : {"2", "3", "0", "64"}) {
    const Outcome r = run(scene + " --threads " + threads + " -o many.ppm --stats many.json");
    ASSERT_EQ(r.exit_code, 0) << threads << ": " << r.err;
    EXPECT_TRUE(read_file(dir_ / "many.ppm") == read_file(dir_ / "one.ppm")) << threads;
    const Json many = Json::parse(read_file(dir_ / "many.json"));
    EXPECT_EQ(many.at("rays"), one.at("rays")) << threads;
    EXPECT_EQ(many.at("tests"), one.at("tests")) << threads;
    EXPECT_EQ(many.at("pages"), one.at("pages")) << threads;
  }
  // More threads than rows: as many as there are rows.
  EXPECT_EQ(Json::parse(read_file(dir_ / "many.json")).at("render_threads"), 20);
  const Outcome r = run("teapot:2 --width 24 --height 20 --single --threads 2 -o out.ppm");
  EXPECT_NE(r.out.find("on 2 threads"), std::string::npos) << r.out;
}

TEST_F(MachineCli, EachBadInputIsOneLineWithNoOutputFile) {
  const std::vector<std::pair<std::string, int>> cases{
      {"--cache-pages 0", 2},
      {"--cache-kb 0", 2},
      {"--cache-kb 1 --page-size 2048", 2},
      {"--page-size 1000", 2},
      {"--page-size 128", 2},
      {"--topology hypercube --nodes 6", 2},
      {"--topology mesh:4x4 --nodes 8", 2},
      {"--topology star:4", 2},
      {"--schedule random", 2},
      {"--pixel-order spiral", 2},
      {"--distribution stripes", 2},
      {"--grain 0", 2},
      {"--prefetch 4", 2},
      {"no/such/scene.nff", 1},
  };
  for (const auto& [args, code] : cases) {
    const Outcome r = run(args + " --width 8 --height 8 -o out.png --stats s.json");
    EXPECT_EQ(r.exit_code, code) << args;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out.png")) << args;
    EXPECT_FALSE(fs::exists(dir_ / "s.json")) << args;
  }
}

// Outputs are written after the render; when one cannot be, the run fails
// with one line naming it, and the files written before it are removed.
TEST_F(MachineCli, AnOutputThatCannotBeWrittenLeavesNoOtherFile) {
  const std::vector<std::string> cases{
      "--stats nodir/s.json",
      "--stats s.json --tiles t.csv --timeline nodir/t.svg",
      "--stats s.json --machine-svg m.svg --ownership o.png --report nodir/r.html",
  };
  for (const std::string& args : cases) {
    const Outcome r = run(std::string(kSmall) + " -q -o out.png " + args);
    EXPECT_EQ(r.exit_code, 2) << args;  // refused before the scene is read (output_check.hpp)
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_NE(r.err.find("nodir/"), std::string::npos) << args << ": " << r.err;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      EXPECT_TRUE(name.starts_with("std")) << args << " left " << name;  // only the captured stdout and stderr
    }
  }
}

// The report on standard output is part of the run's output: when it cannot
// be written (a full device, a closed descriptor) the run fails and takes
// its files with it.
TEST_F(MachineCli, AReportThatCannotBePrintedFailsTheRun) {
  for (const char* target : {"/dev/full", "&-"}) {
    const Outcome r = run_vmpray(std::string(kSmall) + " -o out.png --stats s.json --machine-svg m.svg", target);
    EXPECT_EQ(r.exit_code, 1) << target;
    EXPECT_EQ(lines(r.err), 1u) << target << ": " << r.err;
    EXPECT_NE(r.err.find("standard output"), std::string::npos) << target << ": " << r.err;
    for (const char* name : {"out.png", "s.json", "m.svg"}) EXPECT_FALSE(fs::exists(dir_ / name)) << target << " " << name;
  }
}

// The help and the version are the output of their runs: unwritten, they fail.
TEST_F(MachineCli, HelpOrVersionThatCannotBePrintedFails) {
  for (const char* args : {"--help", "--version"})
    for (const char* target : {"/dev/full", "&-"}) {
      const Outcome r = run_vmpray(args, target);
      EXPECT_EQ(r.exit_code, 1) << args << " > " << target;
      EXPECT_EQ(r.err, "vmpray: cannot write to standard output\n") << args << " > " << target;
    }
  EXPECT_EQ(run_vmpray("--help").exit_code, 0);
}

// Two outputs at one path would overwrite each other. Refused before the
// render, leaving nothing.
TEST_F(MachineCli, TwoOutputsAtOnePathAreAnError) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"-o x.png --ownership x.png", "--output and --ownership would both write 'x.png'"},
      {"--stats t.json --tiles ./t.json", "--stats and --tiles would both write './t.json'"},
  };
  for (const auto& [args, message] : cases) {
    const Outcome r = run(std::string(kSmall) + " -q " + args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    for (const auto& entry : fs::directory_iterator(dir_))
      EXPECT_TRUE(entry.path().filename().string().starts_with("std")) << args << " left " << entry.path();
  }
}

// A failed run removes what it wrote, and only that: what stood at a path
// it could not write stays, here an empty directory in the way of --stats.
TEST_F(MachineCli, AFailedRunLeavesWhatItDidNotWrite) {
  fs::create_directory(dir_ / "in_the_way.json");
  const Outcome r = run(std::string(kSmall) + " -q -o out.png --stats in_the_way.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("in_the_way.json"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_directory(dir_ / "in_the_way.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(MachineCli, ErrorsNameTheOption) {
  EXPECT_NE(run("--cache-pages 0").err.find("--cache-pages"), std::string::npos);
  EXPECT_NE(run("--topology ring:8 --nodes 4").err.find("--topology"), std::string::npos);
  EXPECT_NE(run("--page-size 3000").err.find("--page-size"), std::string::npos);
}

TEST_F(MachineCli, TraceRoutesPrintsThatManyRouteLines) {
  // The first packets injected, whichever processes sent them, under a heading.
  for (const char* machine : {"", " --topology ring --nodes 8", " --nodes 64"}) {
    const Outcome many = run(std::string(kSmall) + machine + " -q --trace-routes 40 -o out.png");
    ASSERT_EQ(many.exit_code, 0) << machine << ": " << many.err;
    EXPECT_EQ(lines(many.out), 41u) << machine;
    EXPECT_EQ(many.out.rfind("routes         40 packets traced, hop by hop:\n", 0), 0u) << many.out;
  }
  const Outcome r = run(std::string(kSmall) + " -q --trace-routes 3 -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 4u) << r.out;
  std::istringstream in(r.out);
  std::string line;
  std::getline(in, line);  // the heading
  // "  page_request 17: 5 → 4 → 6 → 7 (3 hops)", "(1 hop)" for one.
  for (; std::getline(in, line);) {
    EXPECT_EQ(line.rfind("  ", 0), 0u) << line;
    EXPECT_NE(line.find(" hop"), std::string::npos) << line;
    EXPECT_TRUE(line.ends_with(")")) << line;
  }
}

// --trace-kind picks the packets traced: page traffic, which the first
// packets (farming messages) never reach in a short trace; the JSON holds
// each route as its node numbers.
TEST_F(MachineCli, TraceKindTracesPacketsOfThoseKindsOnly) {
  const Outcome r =
      run(std::string(kSmall) + " -q --cache-pages 1 --trace-routes 5 --trace-kind page_request -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 6u) << r.out;
  std::istringstream in(r.out);
  std::string line;
  std::getline(in, line);
  for (; std::getline(in, line);) EXPECT_EQ(line.rfind("  page_request ", 0), 0u) << line;
  const Json routes = Json::parse(read_file(dir_ / "s.json")).at("machine").at("routes");
  ASSERT_EQ(routes.size(), 5u);
  std::set<std::uint64_t> ids;
  for (const Json& route : routes) {
    EXPECT_EQ(route.at("kind").get<std::string>(), "page_request");
    ASSERT_TRUE(route.at("id").is_number_unsigned()) << route;
    EXPECT_TRUE(ids.insert(route.at("id").get<std::uint64_t>()).second) << "two routes of packet " << route.at("id");
    ASSERT_GE(route.at("nodes").size(), 2u);
    for (const Json& node : route.at("nodes")) {
      EXPECT_TRUE(node.is_number_unsigned());
      EXPECT_LT(node.get<double>(), 16);
    }
  }
  const Outcome both = run(std::string(kSmall) + " -q --trace-routes 4 --trace-kind page_request,page_reply -o out.png");
  ASSERT_EQ(both.exit_code, 0) << both.err;
  EXPECT_EQ(lines(both.out), 5u) << both.out;
}

TEST(MachineOptions, TraceKindNamesKnownKindsAndNeedsTraceRoutes) {
  EXPECT_EQ(test::parse({"--trace-routes", "2", "--trace-kind", "page_reply,work"}).machine.observe.trace_kinds,
            (std::vector<std::uint8_t>{6, 2}));
  for (const auto& [args, message] :
       {std::pair<std::vector<const char*>, std::string>{
            {"--trace-routes", "2", "--trace-kind", "page"},
            "--trace-kind: expected packet kinds among work_request, work, stop, result, page_request, page_reply, "
            "worker_done, server_stop, server_done, got 'page'"},
        {{"--trace-kind", "page_request"}, "--trace-kind: chooses the packets --trace-routes N traces; give that too"}}) {
    try {
      test::parse(args);
      ADD_FAILURE() << message;
    } catch (const app::UsageError& e) {
      EXPECT_EQ(e.what(), message);
    }
  }
}

// One row per tile, in order of start, covering every pixel once; --tiles
// needs a machine.
TEST_F(MachineCli, TilesWritesOneCsvRowPerTile) {
  const Outcome r = run(std::string(kSmall) + " -q --grain 5 -o out.png --tiles tiles.csv --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(read_file(dir_ / "tiles.csv"));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "node,worker,first_item,items,start_s,end_s,page_requests,rays");
  std::vector<int> computed(32 * 32, 0);
  std::size_t rows = 0;
  double previous_start = 0;
  std::uint64_t requests = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::istringstream row(line);
    std::vector<double> f;
    for (std::string field; std::getline(row, field, ',');) f.push_back(std::stod(field));
    ASSERT_EQ(f.size(), 8u) << line;
    EXPECT_GE(f[4], previous_start) << line;
    EXPECT_LE(f[4], f[5]) << line;
    previous_start = f[4];
    for (auto i = static_cast<std::size_t>(f[2]); i < static_cast<std::size_t>(f[2] + f[3]); ++i) ++computed.at(i);
    requests += static_cast<std::uint64_t>(f[6]);
  }
  const Json doc = Json::parse(read_file(dir_ / "s.json"));
  double tiles = 0;
  for (const Json& node : doc.at("machine").at("per_node")) tiles += node.at("tiles").get<double>();
  EXPECT_EQ(rows, static_cast<std::size_t>(tiles));
  EXPECT_EQ(requests, static_cast<std::uint64_t>(doc.at("machine").at("svm").at("misses").get<double>()));
  EXPECT_EQ(std::count(computed.begin(), computed.end(), 1), 32 * 32);

  const Outcome single = run("tetra:3 --width 32 --height 32 --single -o single.png --tiles t.csv");
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_NE(single.err.find("--tiles"), std::string::npos) << single.err;
  EXPECT_FALSE(fs::exists(dir_ / "t.csv"));
}

TEST_F(MachineCli, TimelineIsAnSvgOfAMachineRunAndRefusedWithSingle) {
  const Outcome r = run(std::string(kSmall) + " -q --nodes 8 -o out.png --timeline tiles.svg");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string svg = read_file(dir_ / "tiles.svg");
  EXPECT_TRUE(svg.starts_with("<svg")) << svg.substr(0, 40);
  // Its rows, one per node, are checked from the layout in tests/app/viz/timeline_test.cpp.
  EXPECT_TRUE(svg.ends_with("</svg>\n")) << svg.substr(svg.size() - std::min<std::size_t>(svg.size(), 40));

  const Outcome single = run("tetra:3 --width 32 --height 32 --single -o single.png --timeline t.svg");
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_NE(single.err.find("--timeline"), std::string::npos) << single.err;
}

TEST_F(MachineCli, CompareSerialReportsSpeedupAndEfficiency) {
  const Outcome r = run(std::string(kSmall) + " --nodes 4 --compare-serial -o out.png --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("efficiency"), std::string::npos);
  // Times, speedup and efficiency keep three decimals after the wall-time line.
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(speedup +\d+\.\d{3} \(1 node: \d+\.\d{3} s)"))) << r.out;
  const Json doc = Json::parse(read_file(dir_ / "s.json"));
  const Json& serial = doc.at("machine").at("serial");
  ASSERT_TRUE(serial.is_object());
  EXPECT_GT(serial.at("seconds").get<double>(), 0);
  EXPECT_EQ(serial.at("threads").get<double>(), 1);
  EXPECT_NEAR(serial.at("efficiency").get<double>(), serial.at("speedup").get<double>() / 4, 1e-6);
}

TEST_F(MachineCli, ReportShowsMissRatioPageTrafficAndPerNodeTable) {
  const Outcome r = run(std::string(kSmall) + " --topology ring:4 -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* field : {"miss ratio", "page communications", "distinct pages per pixel",
                            "imbalance", "busiest link", "wall time"})
    EXPECT_NE(r.out.find(field), std::string::npos) << field;
}

// The page is one file that holds its images and says what made it.
TEST_F(MachineCli, ReportIsOnePageThatSaysWhatMadeIt) {
  const Outcome r = run(std::string(kSmall) + " --topology ring:4 -q -o out.png --report run.html");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::set<std::string> written;
  for (const auto& entry : fs::directory_iterator(dir_))
    if (!entry.path().filename().string().starts_with("std")) written.insert(entry.path().filename().string());
  EXPECT_EQ(written, (std::set<std::string>{"out.png", "run.html"}));
  const std::string html = test::read_file(dir_ / "run.html");
  EXPECT_NE(html.find("Made by vmpray " VMPRAY_VERSION " with <code>"), std::string::npos);
  EXPECT_NE(html.find(std::string(kSmall) + " --topology ring:4 -q -o out.png --report run.html</code>"),
            std::string::npos);
  EXPECT_NE(html.find("<img src=\"data:image/png;base64,"), std::string::npos);
}

using test::parse;

TEST(MachineOptions, DefaultIsASixteenNodeHypercubeWithTheDefaultCache) {
  const app::Options o = parse({});
  EXPECT_FALSE(o.single);
  EXPECT_EQ(o.machine.topology.spec(), "hypercube:4");
  EXPECT_EQ(o.machine.topology.size(), 16u);
  EXPECT_FALSE(o.machine.cache.pages);
  EXPECT_FALSE(o.machine.cache.kb);
  EXPECT_EQ(o.machine.farming.schedule, nodes::Schedule::affinity);
  EXPECT_EQ(o.machine.farming.pixel_order, nodes::PixelOrder::hilbert);
  EXPECT_EQ(o.machine.shape.distribution, nodes::Distribution::modulo);
}

TEST(MachineOptions, AFullSpecNeedsNoNodeCount) {
  const app::Options o = parse({"--topology", "mesh:4x2"});
  EXPECT_EQ(o.machine.topology.spec(), "mesh:4x2");
  EXPECT_EQ(o.machine.topology.size(), 8u);  // not the default 16
  EXPECT_EQ(parse({"--topology", "torus:2x2", "--nodes", "4"}).machine.topology.size(), 4u);
}

TEST(MachineOptions, ValuesReachTheMachine) {
  const app::Options o = parse({"--cache-kb", "8", "--grain", "9", "--schedule", "dynamic",
                                "--workers-per-node", "3", "--distribution", "block",
                                "--trace-routes", "5", "--threads", "2", "--compare-serial", "--prefetch", "2"});
  EXPECT_EQ(o.machine.cache.kb, 8u);
  EXPECT_EQ(o.machine.farming.grain, 9u);
  EXPECT_EQ(o.machine.farming.schedule, nodes::Schedule::dynamic);
  EXPECT_EQ(parse({"--schedule", "static"}).machine.farming.schedule, nodes::Schedule::static_split);
  EXPECT_EQ(parse({"--schedule", "affinity"}).machine.farming.schedule, nodes::Schedule::affinity);
  EXPECT_EQ(parse({"--pixel-order", "scanline"}).machine.farming.pixel_order, nodes::PixelOrder::scanline);
  EXPECT_EQ(parse({"--schedule", "dynamic"}).machine.farming.schedule, nodes::Schedule::dynamic);
  EXPECT_EQ(o.machine.shape.workers_per_node, 3);
  EXPECT_EQ(o.machine.shape.distribution, nodes::Distribution::block);
  EXPECT_EQ(o.machine.observe.trace_routes, 5u);
  EXPECT_EQ(o.machine.threads.count, 2u);
  EXPECT_EQ(o.machine.farming.prefetch, 2);
  EXPECT_TRUE(o.compare_serial);
}

TEST(MachineOptions, BothCacheSizesIsAnError) {
  EXPECT_THROW(parse({"--cache-pages", "4", "--cache-kb", "4"}), app::UsageError);
}

}  // namespace
