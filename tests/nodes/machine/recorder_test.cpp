// The recorder's invariants on whole machine runs: every recorded hop crosses
// a link of the topology along the route topology::next_hop gives, no packet
// arrives before it left, the packets recorded and counted are the routers'
// own per kind, the pages waited for and served and the page hits match the
// node reports, and
// a bound records the first packets hop by hop, and the waits and serves
// begun while it lasts, and only counts the rest.
#include "nodes/machine/recorder.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "nodes/machine/machine.hpp"
#include "tests/nodes/machine/test_database.hpp"
#include "topology/spec.hpp"

namespace {

struct RecordedRun {
  nodes::MachineResult result;
  topology::Topology topology;
};

RecordedRun recorded_run(const std::string& spec, std::size_t nodes, bool virtual_time, std::uint64_t max_packets,
                         unsigned threads = 1, int workers = 1) {
  nodes::MachineOptions options;
  options.topology = topology::parse_topology(spec, nodes);
  options.threads.count = threads;
  options.shape.workers_per_node = workers;
  options.cache.pages = 8;
  options.observe.record = true;
  options.observe.record_packets = max_packets;
  if (virtual_time) options.timing = nodes::profile_named("ipsc2");
  auto result = nodes::run_machine(test::make_db("teapot:2", 1024, 24), options);
  return {std::move(result), topology::parse_topology(spec, nodes)};
}

// The route next_hop takes from a packet's source to its destination.
std::vector<topology::NodeId> routed(const topology::Topology& t, topology::NodeId from, topology::NodeId to) {
  std::vector<topology::NodeId> route{from};
  while (route.back() != to) route.push_back(t.neighbour(route.back(), t.next_hop(route.back(), to).port));
  return route;
}

void expect_consistent(const RecordedRun& run) {
  const nodes::MachineReport& report = run.result.report;
  ASSERT_NE(report.recording, nullptr);
  const nodes::Recording& rec = *report.recording;
  std::map<std::uint8_t, std::uint64_t> recorded;
  double last_injection = 0;
  for (const nodes::PacketTrace& p : rec.packets) {
    ++recorded[p.kind];
    ASSERT_EQ(p.times.size(), 2 * p.route.size());
    EXPECT_EQ(p.route, routed(run.topology, p.route.front(), p.route.back())) << "packet " << p.id;
    for (std::size_t h = 0; h < p.hops(); ++h) {
      const auto next = run.topology.neighbours(p.route[h]);
      EXPECT_NE(std::find(next.begin(), next.end(), p.route[h + 1]), next.end());
      EXPECT_GE(p.departs(h), h == 0 ? p.injected() : p.arrives(h - 1));
      EXPECT_GE(p.arrives(h), p.departs(h));
    }
    EXPECT_GE(p.delivered(), p.injected());
    EXPECT_LE(p.delivered(), rec.end);
    EXPECT_GE(p.injected(), last_injection) << "packets go by injection time";
    last_injection = p.injected();
  }
  // Recorded and counted together: the routers' packets and hops, kind by kind.
  for (const auto& [kind, hops] : report.network.hops_by_kind)
    EXPECT_EQ(recorded[kind] + rec.unrecorded[kind], hops.packets) << "kind " << int(kind);
  EXPECT_EQ(rec.packets.size() + rec.unrecorded_packets, report.network.hops.packets);
  EXPECT_EQ(rec.recorded_hops() + rec.unrecorded_hops, report.network.hops.total_hops);
  // Every miss waited once, every page served once; tiles as the node reports.
  std::uint64_t items = 0;
  for (std::size_t n = 0; n < rec.nodes.size(); ++n) {
    const nodes::NodeTrace& node = rec.nodes[n];
    EXPECT_EQ(node.fetches.size() + node.unrecorded_fetches, report.per_node[n].svm.misses) << "node " << n;
    EXPECT_EQ(node.serves.size() + node.unrecorded_serves, report.per_node[n].served.pages_served) << "node " << n;
    for (const auto& f : node.fetches) EXPECT_LE(f.start, f.end);
    for (const auto& s : node.serves) EXPECT_LE(s.start, s.end);
    // Waits and serves are recorded while the packet budget lasts: begun in the window.
    for (const auto& f : node.fetches) EXPECT_LE(f.start, rec.window);
    for (const auto& s : node.serves) EXPECT_LE(s.start, rec.window);
    for (const auto& t : node.tiles) items += t.tile.count;
    // Every page call falls in a tile: each worker's last sample is its total.
    std::map<std::uint16_t, std::uint64_t> last;
    for (const auto& h : node.hits) {
      EXPECT_GE(h.hits, last[h.worker]);
      last[h.worker] = h.hits;
    }
    std::uint64_t hits = 0;
    for (const auto& [worker, h] : last) hits += h;
    EXPECT_EQ(hits, report.per_node[n].svm.own_hits + report.per_node[n].svm.cache_hits) << "node " << n;
    EXPECT_EQ(node.hits.size(), node.tiles.size());
  }
  EXPECT_EQ(items, report.items_computed());
}

TEST(Recorder, HopsFollowTheRoutesOfAHypercubeInVirtualTime) {
  const RecordedRun run = recorded_run("hypercube", 8, true, 1u << 20);
  expect_consistent(run);
  EXPECT_TRUE(run.result.report.recording->virtual_time);
  EXPECT_EQ(run.result.report.recording->unrecorded_packets, 0u);
  // In virtual time a hop takes the link's time: 175 us at least.
  for (const auto& p : run.result.report.recording->packets)
    for (std::size_t h = 0; h < p.hops(); ++h) EXPECT_GE(p.arrives(h) - p.departs(h), 175e-6 - 1e-12);
}

TEST(Recorder, HopsFollowTheRoutesOfATorusOnTwoThreads) {
  const RecordedRun run = recorded_run("torus:4x2", 8, false, 1u << 20, 2, 2);
  expect_consistent(run);
  EXPECT_FALSE(run.result.report.recording->virtual_time);
}

TEST(Recorder, ARingAndAMeshInRealTime) {
  expect_consistent(recorded_run("ring", 6, false, 1u << 20));
  expect_consistent(recorded_run("mesh:3x2", 6, false, 1u << 20));
}

TEST(Recorder, VirtualTimeRecordsTheSameRunTwice) {
  const RecordedRun a = recorded_run("mesh:2x2", 4, true, 1u << 20);
  const RecordedRun b = recorded_run("mesh:2x2", 4, true, 1u << 20);
  const auto& pa = a.result.report.recording->packets;
  const auto& pb = b.result.report.recording->packets;
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa[i].id, pb[i].id);
    EXPECT_EQ(pa[i].times, pb[i].times);
  }
}

TEST(Recorder, ABoundRecordsTheFirstPacketsAndCountsTheRest) {
  const RecordedRun run = recorded_run("hypercube", 8, true, 50);
  expect_consistent(run);
  const nodes::Recording& rec = *run.result.report.recording;
  EXPECT_EQ(rec.packets.size(), 50u);
  EXPECT_EQ(rec.max_packets, 50u);
  EXPECT_GT(rec.unrecorded_packets, 0u);
  // In virtual time the first packets are the first in time: the work
  // requests, which every pixel computer sends as it starts, are all there.
  std::uint64_t work_requests = 0;
  for (const auto& p : rec.packets) work_requests += p.kind == std::uint8_t(nodes::MessageKind::work_request);
  EXPECT_EQ(work_requests, 8u);
}

// Everything recorded that grows with the run is bounded by the budget:
// waits and serves begin while packets are still recorded (each such wait
// sends a request the budget took, but for the few in flight as it ran out),
// and only tile-sized records remain beyond it.
void expect_bounded(const RecordedRun& run, std::uint64_t budget) {
  const nodes::Recording& rec = *run.result.report.recording;
  std::uint64_t fetches = 0, serves = 0, misses = 0, unrecorded = 0;
  for (const nodes::NodeTrace& node : rec.nodes) {
    fetches += node.fetches.size();
    serves += node.serves.size();
    unrecorded += node.unrecorded_fetches;
  }
  for (const auto& node : run.result.report.per_node) misses += node.svm.misses;
  const std::uint64_t in_flight = rec.nodes.size() * 2 * static_cast<std::uint64_t>(run.result.report.workers_per_node);
  EXPECT_LE(fetches, budget + in_flight);
  EXPECT_LE(serves, budget + in_flight);
  EXPECT_EQ(fetches + unrecorded, misses);
  EXPECT_EQ(unrecorded, rec.unrecorded_fetches);
  EXPECT_GT(rec.unrecorded_fetches, 0u);
  EXPECT_GT(rec.unrecorded_serves, 0u);
  EXPECT_LT(rec.window, rec.end);
}

TEST(Recorder, TheBudgetBoundsWaitsAndServesToo) {
  for (const bool virtual_time : {true, false}) {
    const RecordedRun run = recorded_run("hypercube", 8, virtual_time, 40);
    expect_consistent(run);
    expect_bounded(run, 40);
  }
  const RecordedRun split = recorded_run("torus:4x2", 8, false, 40, 2, 2);
  expect_consistent(split);
  expect_bounded(split, 40);
}

TEST(Recorder, ABudgetOfNoneCountsEveryPacket) {
  const RecordedRun run = recorded_run("ring", 4, false, 0);
  expect_consistent(run);
  EXPECT_TRUE(run.result.report.recording->packets.empty());
}

TEST(Recorder, AnUnrecordedRunHasNoRecording) {
  nodes::MachineOptions options;
  options.topology = topology::parse_topology("hypercube", 4);
  options.threads.count = 1;
  const auto result = nodes::run_machine(test::make_db("teapot:2", 1024, 16), options);
  EXPECT_EQ(result.report.recording, nullptr);
}

TEST(Recorder, TheBudgetIsTakenOncePerPacket) {
  nodes::Recorder recorder(2, 3, false);
  EXPECT_TRUE(recorder.admit());
  EXPECT_TRUE(recorder.admit());
  EXPECT_TRUE(recorder.admit());
  EXPECT_FALSE(recorder.admit());
  EXPECT_FALSE(recorder.admit());
}

TEST(Recorder, MergeRefusesAHopBetweenNodesThatAreNotNeighbours) {
  const auto ring = topology::Topology::ring(4);
  nodes::Recorder recorder(4, 10, false);
  recorder.log(0).injected.push_back({7, 0.0, 2, 0, 1});
  // Node 0 leaves by its port 0, then the packet "arrives" at node 2, two nodes away.
  recorder.log(0).departed.push_back({7, 1.0, 0, 0});
  recorder.log(2).arrived.push_back({7, 2.0, 0, 1});
  recorder.log(2).delivered.push_back({7, 3.0, 1});
  EXPECT_THROW(nodes::merge_recording(recorder, ring, {}), std::logic_error);
}

TEST(Recorder, MergeRefusesAnArrivalBeforeTheDeparture) {
  const auto ring = topology::Topology::ring(4);
  nodes::Recorder recorder(4, 10, false);
  const topology::NodeId next = ring.neighbour(0, 0);
  recorder.log(0).injected.push_back({7, 0.0, next, 0, 1});
  recorder.log(0).departed.push_back({7, 2.0, 0, 0});
  recorder.log(next).arrived.push_back({7, 1.0, 0, 1});
  recorder.log(next).delivered.push_back({7, 3.0, 1});
  EXPECT_THROW(nodes::merge_recording(recorder, ring, {}), std::logic_error);
  recorder.log(next).arrived.back().time = 2.5;
  const nodes::Recording ok = nodes::merge_recording(recorder, ring, {});
  ASSERT_EQ(ok.packets.size(), 1u);
  EXPECT_EQ(ok.packets[0].route, (std::vector<topology::NodeId>{0, next}));
  EXPECT_EQ(ok.end, 3.0);
}

TEST(Recorder, MergeRefusesAPacketNeverDelivered) {
  nodes::Recorder recorder(2, 10, false);
  recorder.log(0).injected.push_back({3, 0.0, 1, 0, 1});
  EXPECT_THROW(nodes::merge_recording(recorder, topology::Topology::complete(2), {}), std::logic_error);
}

}  // namespace
