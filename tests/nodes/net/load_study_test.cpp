// The load study (nodes/net/load_study.hpp) against what can be worked out
// without it: at zero load a packet takes (hops + 1) message times, store
// and forward, and its hops are the topology's distance; below saturation
// the network accepts what is offered; Little's law ties the packets in
// flight to throughput and latency; no load, however far past saturation,
// loses, duplicates or misdelivers a packet or fails to end; under uniform
// traffic accepted throughput never passes the channel-load bound; a run
// repeats exactly.
#include "nodes/net/load_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "topology/spec.hpp"

namespace {

using nodes::LoadResult;
using nodes::TrafficPattern;

nodes::LoadStudyOptions small_options() {
  nodes::LoadStudyOptions o;
  o.link = nodes::LinkModel{std::chrono::microseconds(10), 10e6};  // 10 µs + 6.4 µs for 64 bytes
  o.payload_bytes = 64;
  return o;
}

double message_time(const nodes::LoadStudyOptions& o) { return nodes::zero_load_latency(o.link, o.payload_bytes, 0); }

// Packets per node per second at `fraction` of the channel-load bound.
double offered_at(const topology::Topology& t, TrafficPattern p, const nodes::LoadStudyOptions& o, double fraction) {
  return fraction / (message_time(o) * nodes::max_channel_load(t, p, o.hotspot_fraction));
}

void expect_nothing_lost(const LoadResult& r, const std::string& what) {
  EXPECT_GT(r.created, 0u) << what;
  EXPECT_EQ(r.delivered, r.created) << what;
  EXPECT_EQ(r.misdelivered, 0u) << what;
}

TEST(LoadStudy, AtZeroLoadAPacketTakesItsHopsPlusOneMessageTimes) {
  nodes::LoadStudyOptions o = small_options();
  const double message = message_time(o);
  o.window_seconds = 2e7 * message;  // some 20 packets from every node, never two on a link at once
  EXPECT_NEAR(message, 16.4e-6, 1e-12);
  for (const char* spec : {"hypercube:4", "mesh:4x4", "torus:4x4", "ring:16", "complete:16"}) {
    const topology::Topology t = topology::parse_topology(spec);
    for (const TrafficPattern p : {TrafficPattern::bit_complement, TrafficPattern::transpose, TrafficPattern::neighbour,
                                   TrafficPattern::uniform}) {
      const std::string what = std::string(spec) + " " + nodes::pattern_name(p);
      const LoadResult r = nodes::run_load(t, p, 1e-6 / message, o);
      expect_nothing_lost(r, what);
      ASSERT_GT(r.measured, 0u) << what;
      // No packet waited: every latency is exactly (hops + 1) message times.
      EXPECT_NEAR(r.mean_latency, (r.mean_hops + 1) * message, 1e-9 * r.mean_latency) << what;
      // Minimal routing: the hops are the distances; the longest is the pattern's.
      unsigned longest = 0;
      const auto to = nodes::fixed_destinations(p, t);
      for (topology::NodeId n = 0; n < to.size(); ++n) longest = std::max(longest, t.distance(n, to[n]));
      if (p == TrafficPattern::uniform) longest = t.diameter();
      EXPECT_LE(r.max_latency, (longest + 1) * message + 1e-12) << what;
      if (p != TrafficPattern::uniform) {
        EXPECT_NEAR(r.max_latency, (longest + 1) * message, 1e-9) << what;
      }
    }
  }
  // Uniform traffic's mean hops are the average distance.
  const topology::Topology cube = topology::parse_topology("hypercube:6");
  const LoadResult uniform = nodes::run_load(cube, TrafficPattern::uniform, 0.002 / message, small_options());
  EXPECT_NEAR(uniform.mean_hops, cube.average_distance(), 0.03 * cube.average_distance());
}

TEST(LoadStudy, BelowSaturationTheNetworkAcceptsWhatIsOfferedAndLittlesLawHolds) {
  const nodes::LoadStudyOptions o = small_options();
  for (const char* spec : {"hypercube:6", "torus:8x8", "mesh:8x8", "ring:16"}) {
    const topology::Topology t = topology::parse_topology(spec);
    for (const double fraction : {0.2, 0.5}) {
      const std::string what = std::string(spec) + " at " + std::to_string(fraction);
      const double offered = offered_at(t, TrafficPattern::uniform, o, fraction);
      const LoadResult r = nodes::run_load(t, TrafficPattern::uniform, offered, o);
      expect_nothing_lost(r, what);
      EXPECT_NEAR(r.accepted, offered, 0.02 * offered) << what;
      EXPECT_NEAR(r.mean_in_flight, r.arrival_rate * r.mean_latency, 0.02 * r.mean_in_flight) << what;
      EXPECT_GT(r.mean_latency, nodes::zero_load_latency(o.link, o.payload_bytes, 0)) << what;
    }
  }
}

TEST(LoadStudy, PastSaturationNothingIsLostAndThroughputStaysUnderTheBound) {
  const nodes::LoadStudyOptions o = small_options();
  for (const char* spec : {"hypercube:4", "torus:4x4", "mesh:4x4", "ring:16", "complete:16"}) {
    const topology::Topology t = topology::parse_topology(spec);
    for (const TrafficPattern p : {TrafficPattern::uniform, TrafficPattern::hotspot, TrafficPattern::tornado}) {
      if (!nodes::pattern_unfit(p, t).empty()) continue;
      const std::string what = std::string(spec) + " " + nodes::pattern_name(p);
      const double bound = offered_at(t, p, o, 1.0);
      const LoadResult r = nodes::run_load(t, p, 2 * bound, o);
      expect_nothing_lost(r, what);
      // Uniform traffic saturates every node alike, so no node gets past the busiest link's bound; under a
      // hotspot the other nodes' traffic goes on past the point where node 0's delivery saturates.
      if (p == TrafficPattern::uniform) {
        EXPECT_LE(r.accepted, 1.02 * bound) << what;
      }
      EXPECT_LT(r.accepted, 0.9 * r.offered) << what;
      EXPECT_GT(r.mean_latency, 5 * nodes::zero_load_latency(o.link, o.payload_bytes, t.diameter())) << what;
    }
  }
}

TEST(LoadStudy, ARunRepeatsExactly) {
  const nodes::LoadStudyOptions o = small_options();
  const topology::Topology t = topology::parse_topology("torus:4x4");
  const double offered = offered_at(t, TrafficPattern::uniform, o, 0.7);
  const LoadResult a = nodes::run_load(t, TrafficPattern::uniform, offered, o);
  const LoadResult b = nodes::run_load(t, TrafficPattern::uniform, offered, o);
  EXPECT_EQ(a.created, b.created);
  EXPECT_EQ(a.mean_latency, b.mean_latency);
  EXPECT_EQ(a.p99_latency, b.p99_latency);
  EXPECT_EQ(a.accepted, b.accepted);
  nodes::LoadStudyOptions other = o;
  other.seed = 2;
  EXPECT_NE(nodes::run_load(t, TrafficPattern::uniform, offered, other).created, a.created);
}

TEST(LoadStudy, ChannelLoadsOfKnownCases) {
  // Neighbour traffic on a ring: every link and every delivery channel carries one packet a second.
  EXPECT_DOUBLE_EQ(nodes::max_channel_load(topology::parse_topology("ring:16"), TrafficPattern::neighbour, 0), 1.0);
  // Uniform on a complete graph: a link carries 1/(N-1), a node's delivery channel all N-1 of them.
  EXPECT_DOUBLE_EQ(nodes::max_channel_load(topology::parse_topology("complete:8"), TrafficPattern::uniform, 0), 1.0);
  // Uniform on a ring of 16 (shorter way round, ties +1): the busiest link carries 36 of the 15 x 16 routes
  // that cross it, each 1/15.
  const double ring = nodes::max_channel_load(topology::parse_topology("ring:16"), TrafficPattern::uniform, 0);
  EXPECT_NEAR(ring, 36.0 / 15.0, 1e-12);
  // Hotspot: node 0's delivery channel takes the share of every other node, and its uniform part.
  EXPECT_NEAR(nodes::max_channel_load(topology::parse_topology("complete:8"), TrafficPattern::hotspot, 0.5),
              7 * 0.5 + 7 * 0.5 / 7, 1e-12);
}

// Recorded traffic: node 0 sends to 1 (64 bytes) and to 2 (1024 bytes) in
// turn on a ring of 4; node 3 sends to 1 (64 bytes); nodes 1 and 2 send nothing.
nodes::RecordedTraffic small_recording() {
  nodes::RecordedTraffic r;
  r.by_source = {{{1, 64}, {2, 1024}}, {}, {}, {{1, 64}}};
  return r;
}

TEST(LoadStudy, RecordedTrafficTakesItsDestinationsAndSizesAtZeroLoad) {
  const topology::Topology ring = topology::parse_topology("ring:4");
  nodes::LoadStudyOptions o = small_options();
  o.recorded = std::make_shared<const nodes::RecordedTraffic>(small_recording());
  const auto seconds = [&o](std::size_t bytes) { return nodes::zero_load_latency(o.link, bytes, 0); };
  // Its packets, each alike: 0->1 (1 hop) and 3->1 (2 hops) of 64 bytes, 0->2 (2 hops) of 1 KB.
  const double zero = (2 * seconds(64) + 3 * seconds(1024) + 3 * seconds(64)) / 3;
  EXPECT_NEAR(nodes::recorded_zero_load_latency(ring, *o.recorded, o.link), zero, 1e-15);
  o.window_seconds = 2e7 * seconds(1024);
  const LoadResult r = nodes::run_load(ring, TrafficPattern::recorded, 1e-6 / seconds(1024), o);
  expect_nothing_lost(r, "recorded");
  ASSERT_GT(r.measured, 30u);
  // Node 0 sends two packets for node 3's one, in its order: the latencies
  // come out in three values, in the recording's proportions.
  EXPECT_NEAR(r.mean_latency, zero, 0.15 * zero);
  EXPECT_NEAR(r.max_latency, 3 * seconds(1024), 1e-12);
  EXPECT_NEAR(r.mean_hops, 5.0 / 3, 0.2);
}

TEST(LoadStudy, RecordedTrafficBelowSaturationIsAcceptedAndItsBoundCountsSizes) {
  const topology::Topology ring = topology::parse_topology("ring:4");
  nodes::LoadStudyOptions o = small_options();
  const nodes::RecordedTraffic traffic = small_recording();
  o.recorded = std::make_shared<const nodes::RecordedTraffic>(traffic);
  // At a mean of one packet a second per node the 4 nodes offer 4: node 0
  // two thirds of them, half to 2 (1 KB), node 3 a third. Link 0->1 is the
  // busiest: both of node 0's, and node 3's to 1 (3->0->1, ties go up).
  // In 64-byte message times: (4/3)(1 + 1024's/64's) + 4/3.
  const double unit = nodes::zero_load_latency(o.link, 64, 0), big = nodes::zero_load_latency(o.link, 1024, 0);
  const double load = nodes::recorded_channel_load(ring, traffic, o.link, 64);
  EXPECT_NEAR(load, 4.0 / 3 * (1 + big / unit) + 4.0 / 3, 1e-12);
  o.window_seconds = 2000 * big / 0.5;  // some thousands of packets
  const double offered = 0.5 / (unit * load);
  const LoadResult r = nodes::run_load(ring, TrafficPattern::recorded, offered, o);
  expect_nothing_lost(r, "recorded at half its bound");
  EXPECT_NEAR(r.accepted, offered, 0.02 * offered);
  EXPECT_NEAR(r.mean_in_flight, r.arrival_rate * r.mean_latency, 0.02 * r.mean_in_flight);
  // Past the bound nothing is lost either, and the run ends.
  expect_nothing_lost(nodes::run_load(ring, TrafficPattern::recorded, 3 * offered / 0.5, o), "recorded past");
}

TEST(LoadStudy, RecordedTrafficMustFitItsTopology) {
  nodes::LoadStudyOptions o = small_options();
  o.recorded = std::make_shared<const nodes::RecordedTraffic>(small_recording());
  EXPECT_THROW(nodes::run_load(topology::parse_topology("ring:8"), TrafficPattern::recorded, 1, o),
               std::invalid_argument);
  nodes::RecordedTraffic to_itself;
  to_itself.by_source = {{{0, 8}}, {}};
  EXPECT_THROW(nodes::recorded_channel_load(topology::parse_topology("ring:2"), to_itself, o.link, 64),
               std::invalid_argument);
  nodes::RecordedTraffic empty;
  empty.by_source.resize(2);
  EXPECT_THROW(nodes::recorded_zero_load_latency(topology::parse_topology("ring:2"), empty, o.link),
               std::invalid_argument);
  o.recorded.reset();
  EXPECT_THROW(nodes::run_load(topology::parse_topology("ring:4"), TrafficPattern::recorded, 1, o),
               std::invalid_argument);
  EXPECT_THROW(nodes::max_channel_load(topology::parse_topology("ring:4"), TrafficPattern::recorded, 0),
               std::invalid_argument);
}

TEST(LoadStudy, PatternsThatDoNotFitAreRefusedByName) {
  const auto why = [](const char* pattern, const char* spec) {
    return nodes::pattern_unfit(nodes::parse_traffic_pattern(pattern), topology::parse_topology(spec));
  };
  EXPECT_EQ(why("bit-reversal", "mesh:3x4"), "bit-reversal traffic needs a power-of-two node count (mesh:3x4 has 12 nodes)");
  EXPECT_EQ(why("transpose", "ring:8"), "transpose traffic needs a square node count, m x m (ring:8 has 8 nodes)");
  EXPECT_EQ(why("tornado", "hypercube:3"), "tornado traffic is not defined on a hypercube: its digits are bits");
  EXPECT_EQ(why("uniform", "ring:8"), "");
  EXPECT_THROW(nodes::parse_traffic_pattern("random"), std::invalid_argument);
  EXPECT_THROW(nodes::run_load(topology::parse_topology("ring:8"), TrafficPattern::uniform, 0, small_options()),
               std::invalid_argument);
  EXPECT_THROW(nodes::run_load(topology::parse_topology("ring:8"), TrafficPattern::uniform, 1, {}),
               std::invalid_argument);
}

}  // namespace
