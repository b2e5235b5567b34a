// Virtual timing of the machine: the cost formula on a hand-computable page
// request, message software per page request and per tile, more hops cost
// more, determinism across runs and thread counts, and the cost/profile
// parsers' errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "nodes/machine/machine.hpp"
#include "nodes/machine/messages.hpp"
#include "nodes/machine/page_server.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "nodes/machine/timing.hpp"
#include "nodes/net/network.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"

namespace {

using nodes::CostModel;
using nodes::Packet;
using nodes::Ports;

tracer::Database make_db(const std::string& spec, int size) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = size;
  scene.camera.height = size;
  return tracer::build_database(scene, {});
}

// Node 0's pixel computer, having counted no work, fetches page 1 from node
// 1's page server over the one link of a two-node machine; returns the
// virtual time at which the page arrived.
double one_page_request(const CostModel& model) {
  constexpr std::uint32_t page_size = 256;
  const nodes::PagePlacement placement(nodes::Distribution::modulo, 2, 2);
  std::vector<std::vector<std::byte>> own(1, std::vector<std::byte>(page_size, std::byte{7}));
  const nodes::NodeMemory memory(placement, 1, page_size, std::move(own), 1);

  nodes::MachineTiming timing(model, 2);
  csp::Runtime runtime(timing.runtime_options(256 * 1024));
  nodes::NetworkOptions net_options;
  net_options.ports_per_node = Ports::count(1);
  net_options.link = model.link_model();
  nodes::Network net(runtime, topology::parse_topology("ring", 2), net_options);
  nodes::ServerCounters served;
  runtime.spawn("server", 0, [&] {
    nodes::PageServer(1, memory, net.port(1, Ports::page_server), nodes::Outbox(net.injector(1, 0), 0, 4), served,
                      timing.serve_hook(1))
        .run();
  });
  double arrived = -1;
  runtime.spawn("worker", 0, [&] {
    nodes::Outbox out(net.injector(0, Ports::first_worker), 1, 4);
    const tracer::RayStats no_work;
    nodes::WorkerPort port(net.port(0, Ports::first_worker));
    const auto charges = timing.charges(0, {&no_work});
    const auto fetch = nodes::make_page_fetch(placement, Ports::first_worker, port, out, charges.get());
    const auto reply = fetch(1);
    arrived = double(csp::this_process::now().count()) * 1e-12;
    EXPECT_EQ(nodes::page_reply_id(reply), 1u);
    out.send(nodes::make_packet(1, Ports::page_server, nodes::MessageKind::server_stop));
    net.port(0, Ports::farmer).read();  // server_done
    net.shutdown();
  });
  runtime.run();
  EXPECT_EQ(served.pages_served, 1u);
  return arrived;
}

TEST(Timing, OnePageRequestCostsExactlyTheModel) {
  CostModel model;
  model.hop = 1e-6;
  model.bandwidth = 1e9;  // one nanosecond per byte
  model.serve = 3e-6;
  const double request = double(nodes::encode_page_request({1, Ports::first_worker}).size());
  const std::vector<std::byte> page(256);
  const double reply = double(nodes::encode_page_reply(1, page).size());
  // Request and reply each cross the link and the delivery stage (store and
  // forward), and the server spends `serve` in between.
  const double expected = 2 * (model.hop + request * 1e-9) + model.serve + 2 * (model.hop + reply * 1e-9);
  EXPECT_NEAR(one_page_request(model), expected, 1e-12);
}

TEST(Timing, MessageSoftwareCostsBothProcessorsTwoMessagesPerPageRequest) {
  CostModel model;
  model.hop = 1e-6;
  model.serve = 3e-6;
  const double free_software = one_page_request(model);
  model.msg = 5e-6;
  // The requester sends the request and receives the page; the owner
  // receives the request and sends the page.
  EXPECT_NEAR(one_page_request(model), free_software + 2 * model.msg + 2 * model.msg, 1e-12);
}

nodes::MachineResult run_timed(const std::string& topology, std::size_t n, unsigned threads,
                               const CostModel& model, bool record_tiles = false, int workers_per_node = 1) {
  nodes::MachineOptions options;
  options.shape.workers_per_node = workers_per_node;
  options.observe.record_tiles = record_tiles;
  options.topology = topology::parse_topology(topology, n);
  options.threads.count = threads;
  options.cache.pages = 4;
  options.timing = model;
  return nodes::run_machine(make_db("teapot:2", 16), options);
}

TEST(Timing, SameRunGivesSamePredictionOnAnyThreadCount) {
  const CostModel model = nodes::ipsc2_profile();
  const auto a = run_timed("hypercube", 8, 1, model);
  const auto b = run_timed("hypercube", 8, 2, model);
  const auto c = run_timed("hypercube", 8, 2, model);
  EXPECT_GT(a.report.predicted_seconds, 0.0);
  for (const auto* r : {&b, &c}) {
    EXPECT_EQ(r->report.predicted_seconds, a.report.predicted_seconds);
    EXPECT_EQ(r->report.compute_seconds, a.report.compute_seconds);
    EXPECT_EQ(r->report.svm().misses, a.report.svm().misses);
    EXPECT_EQ(r->report.network.hops.total_hops, a.report.network.hops.total_hops);
    for (std::size_t n = 0; n < a.report.per_node.size(); ++n)
      EXPECT_EQ(r->report.per_node[n].work.items, a.report.per_node[n].work.items) << "node " << n;
  }
}

// Under virtual time a tile's start and end are virtual clock readings: the
// same on every run, and within the predicted synthesis time.
TEST(Timing, TileTimelineIsVirtualAndTheSameOnAnyThreadCount) {
  const CostModel model = nodes::ipsc2_profile();
  const auto a = run_timed("hypercube", 8, 1, model, true);
  const auto b = run_timed("hypercube", 8, 2, model, true);
  double last_end = 0;
  for (std::size_t n = 0; n < a.report.per_node.size(); ++n) {
    const auto& sa = a.report.per_node[n].work.spans;
    const auto& sb = b.report.per_node[n].work.spans;
    ASSERT_EQ(sa.size(), sb.size()) << "node " << n;
    ASSERT_FALSE(sa.empty()) << "node " << n;
    for (std::size_t i = 0; i < sa.size(); ++i) {
      EXPECT_EQ(sa[i].tile.first, sb[i].tile.first) << "node " << n << " tile " << i;
      EXPECT_EQ(sa[i].start, sb[i].start) << "node " << n << " tile " << i;
      EXPECT_EQ(sa[i].end, sb[i].end) << "node " << n << " tile " << i;
      EXPECT_LT(sa[i].start, sa[i].end) << "node " << n << " tile " << i;
      if (i > 0) {
        EXPECT_LE(sa[i - 1].end, sa[i].start) << "node " << n << " tile " << i;  // one worker: one tile at a time
      }
      last_end = std::max(last_end, sa[i].end);
    }
  }
  EXPECT_LE(last_end, a.report.predicted_seconds);
  EXPECT_GT(last_end, 0.9 * a.report.predicted_seconds);
}

TEST(Timing, MoreHopsCostMore) {
  CostModel model = nodes::ipsc2_profile();
  model.hop = 2e-3;  // make communication dominate
  const auto ring = run_timed("ring", 16, 1, model);
  const auto cube = run_timed("hypercube", 16, 1, model);
  EXPECT_GT(ring.report.network.hops.mean(), cube.report.network.hops.mean());
  EXPECT_GT(ring.report.predicted_seconds, cube.report.predicted_seconds);
}

TEST(Timing, ComputeTimeFollowsCountedWork) {
  CostModel model;
  model.box = 1e-6;
  model.prim = 2e-6;
  model.shade = 3e-6;
  model.page = 4e-6;
  const auto r = run_timed("hypercube", 1, 1, model);
  const tracer::RayStats rays = r.report.rays();
  const double expected = 1e-6 * double(rays.box_tests) + 2e-6 * double(rays.prim_tests) +
                          3e-6 * double(rays.rays()) + 4e-6 * double(rays.page_calls);
  EXPECT_NEAR(r.report.compute_seconds, expected, 1e-9);
  // One node, free messages: the frame takes exactly its compute time.
  EXPECT_NEAR(r.report.predicted_seconds, expected, 1e-9);
}

// A processor's pixel computers share its one CPU: on one node, where no
// page is remote, more of them cannot finish the frame sooner than its
// compute time, which is the same work however it is split.
TEST(Timing, PixelComputersOfANodeShareItsCpu) {
  CostModel model;
  model.box = 1e-6;
  model.prim = 2e-6;
  const auto one = run_timed("hypercube", 1, 1, model);
  for (int workers : {2, 3}) {
    const auto many = run_timed("hypercube", 1, 1, model, false, workers);
    EXPECT_NEAR(many.report.compute_seconds, one.report.compute_seconds, 1e-9) << workers;
    EXPECT_NEAR(many.report.predicted_seconds, one.report.predicted_seconds, 1e-9) << workers;
  }
  // On several nodes they still overlap one another's waits for pages.
  model.hop = 1e-3;
  const auto spread = run_timed("hypercube", 4, 1, model);
  const auto overlapped = run_timed("hypercube", 4, 1, model, false, 2);
  EXPECT_LT(overlapped.report.predicted_seconds, spread.report.predicted_seconds);
}

TEST(Timing, EveryTileCostsTwoMessagesOfSoftware) {
  CostModel model;
  model.box = 1e-6;
  model.msg = 7e-6;
  const auto r = run_timed("hypercube", 1, 1, model);
  const std::uint64_t tiles = r.report.per_node[0].work.tiles;
  ASSERT_GT(tiles, 1u);
  // The work that brings the tile, and the result that asks for the next.
  const double expected = 1e-6 * double(r.report.rays().box_tests) + 7e-6 * 2.0 * double(tiles);
  EXPECT_NEAR(r.report.compute_seconds, expected, 1e-9);
  EXPECT_NEAR(r.report.predicted_seconds, expected, 1e-9);
}

TEST(CostModel, ParsesUnitsAndNamesBadItems) {
  CostModel m;
  nodes::apply_costs(m, "box=2us,prim=1.5e-6,hop=350us,bw=2.8MB/s,serve=0.1ms,msg=175us", "--cost");
  EXPECT_DOUBLE_EQ(m.box, 2e-6);
  EXPECT_DOUBLE_EQ(m.prim, 1.5e-6);
  EXPECT_DOUBLE_EQ(m.hop, 350e-6);
  EXPECT_DOUBLE_EQ(m.bandwidth, 2.8e6);
  EXPECT_DOUBLE_EQ(m.serve, 1e-4);
  EXPECT_DOUBLE_EQ(m.msg, 175e-6);
  nodes::apply_costs(m, "bw = 2.5 MB/s, hop = 20 us", "--cost");  // spaces around the unit
  EXPECT_DOUBLE_EQ(m.bandwidth, 2.5e6);
  EXPECT_DOUBLE_EQ(m.hop, 20e-6);
  // 1e400 does not fit a double: an error, not an escaping std::out_of_range.
  for (const char* bad : {"box", "box=fast", "colour=1", "hop=3 parsecs", "box=-1", "box=1e400s", "box=0x10"}) {
    try {
      nodes::apply_costs(m, bad, "--cost");
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--cost: ", 0), 0u) << e.what();
    }
  }
}

TEST(CostModel, ProfileFileErrorsNameFileAndLine) {
  const std::string path = ::testing::TempDir() + "vmpray_profile_test.txt";
  {
    std::ofstream out(path);
    out << "# a test machine\nprofile = ipsc2\nhop = 10us\n\nbox 3\n";
  }
  try {
    nodes::read_profile_file(path);
    ADD_FAILURE() << "bad line accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ":5: ", 0), 0u) << e.what();
  }
  {
    std::ofstream out(path);
    out << "profile = ipsc2  # base\nhop = 10us\n";
  }
  const CostModel m = nodes::read_profile_file(path);
  EXPECT_DOUBLE_EQ(m.hop, 10e-6);
  EXPECT_DOUBLE_EQ(m.bandwidth, nodes::ipsc2_profile().bandwidth);
  std::remove(path.c_str());
}

TEST(CostModel, ADirectoryIsNoProfile) {
  const std::string dir = ::testing::TempDir();
  try {
    nodes::read_profile_file(dir);
    ADD_FAILURE() << "a directory read as a profile";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), dir + ": is a directory, not a profile");
  }
}

// The last of two settings would win in silence, and a base profile after
// a cost would reset it: both are mistakes in the file.
TEST(CostModel, ProfileFileSetsEachKeyOnceAndItsBaseFirst) {
  const std::string path = ::testing::TempDir() + "vmpray_profile_twice.txt";
  for (const auto& [text, error] : std::vector<std::pair<std::string, std::string>>{
           {"hop = 10us\nbox = 1us\nhop = 20us\n", ":3: hop is already set on line 1"},
           {"bw = 1MB/s\nbandwidth = 2MB/s\n", ":2: bandwidth is already set on line 1"},
           {"hop = 10us\nprofile = ipsc2\n", ":2: 'profile' must come before the costs it is the base of"}}) {
    std::ofstream(path) << text;
    try {
      nodes::read_profile_file(path);
      ADD_FAILURE() << text << " accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), path + error);
    }
  }
  std::remove(path.c_str());
}

}  // namespace
