// The store-and-forward network on csp: storms with buffers of one packet
// on every kind of topology, exact hop counts under all-to-all traffic,
// route tracing, and orderly shutdown.
#include "nodes/net/network.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <memory>
#include <random>

#include "csp/csp.hpp"
#include "topology/spec.hpp"

using namespace nodes;

namespace {

// Destinations of every packet, fixed by the seed; plan[n] lists node n's.
using Plan = std::vector<std::vector<NodeId>>;

Plan random_plan(std::size_t nodes, std::size_t per_node, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<NodeId> pick(0, static_cast<NodeId>(nodes - 1));
  Plan plan(nodes);
  for (auto& dsts : plan)
    for (std::size_t i = 0; i < per_node; ++i) dsts.push_back(pick(rng));
  return plan;
}

Plan all_to_all_plan(std::size_t nodes) {
  Plan plan(nodes);
  for (NodeId n = 0; n < nodes; ++n)
    for (NodeId m = 0; m < nodes; ++m)
      if (m != n) plan[n].push_back(m);
  return plan;
}

// Node n's packets of the plan, numbered on from next_id, each carrying
// `payload` bytes of n.
std::vector<Packet> node_packets(const Plan& plan, NodeId n, std::uint64_t& next_id, std::size_t payload) {
  std::vector<Packet> packets;
  for (NodeId d : plan[n]) {
    Packet p;
    p.destination = d;
    p.kind = kind_traffic;
    p.id = next_id++;
    p.payload.assign(payload, std::byte{static_cast<unsigned char>(n)});
    packets.push_back(std::move(p));
  }
  return packets;
}

// How many packets of the plan each node receives.
std::vector<std::size_t> packets_to_each(const Plan& plan) {
  std::vector<std::size_t> expected(plan.size(), 0);
  for (const auto& dsts : plan)
    for (NodeId d : dsts) ++expected[d];
  return expected;
}

struct Received {
  std::vector<std::uint64_t> ids;
  std::vector<NodeId> sources;  // of each id
  std::uint64_t hops = 0;
  bool misrouted = false;
};

// Runs `plan` over a network; returns what each node received, by node.
// Each node has a sender and a receiver fiber (the consumption assumption);
// the last receiver to finish shuts the network down.
std::vector<Received> run_plan(const topology::Topology& t, const Plan& plan,
                               NetworkOptions options, NetworkStats* stats = nullptr,
                               std::size_t payload = 16, unsigned threads = 2,
                               std::vector<nodes::RelayCounters>* relays = nullptr) {
  csp::Runtime runtime(threads);
  Network net(runtime, t, options);
  const std::vector<std::size_t> expected = packets_to_each(plan);
  std::vector<Received> received(t.size());
  std::atomic<std::size_t> unfinished{t.size()};
  std::uint64_t next_id = 0;
  for (NodeId n = 0; n < t.size(); ++n) {
    std::vector<Packet> packets = node_packets(plan, n, next_id, payload);
    runtime.spawn("send " + std::to_string(n), net.thread_of(n),
                  [out = net.in_place_injector(n), packets = std::move(packets)]() mutable {
                    for (auto& p : packets) out.write(std::move(p));
                  });
    runtime.spawn("receive " + std::to_string(n), net.thread_of(n),
                  [&, n, in = net.port(n)]() mutable {
                    for (std::size_t i = 0; i < expected[n]; ++i) {
                      Packet p = in.read();
                      received[n].ids.push_back(p.id);
                      received[n].sources.push_back(p.source);
                      received[n].hops += p.hops;
                      received[n].misrouted |= p.destination != n || p.hops != t.distance(p.source, n);
                    }
                    if (--unfinished == 0) net.shutdown();
                  });
  }
  runtime.run();
  if (stats) *stats = net.stats();
  if (relays)
    for (unsigned k = 0; k < threads; ++k) relays->push_back(net.relay_counters(k));
  return received;
}

void expect_each_delivered_once(const topology::Topology& t, const Plan& plan,
                                const std::vector<Received>& received) {
  std::size_t total = 0;
  for (const auto& dsts : plan) total += dsts.size();
  std::vector<int> seen(total, 0);
  for (NodeId n = 0; n < t.size(); ++n) {
    EXPECT_FALSE(received[n].misrouted) << t.spec() << " node " << n;
    for (std::uint64_t id : received[n].ids) ++seen.at(id);
  }
  for (std::size_t id = 0; id < total; ++id)
    ASSERT_EQ(seen[id], 1) << t.spec() << " packet " << id;
  // One route per pair and queues kept in order: a sender's packets (ids
  // rising) arrive in the order sent.
  for (NodeId n = 0; n < t.size(); ++n) {
    std::vector<std::uint64_t> last(t.size(), 0);
    std::vector<bool> any(t.size(), false);
    for (std::size_t i = 0; i < received[n].ids.size(); ++i) {
      const NodeId from = received[n].sources[i];
      EXPECT_TRUE(!any[from] || received[n].ids[i] > last[from]) << t.spec() << " " << from << " -> " << n;
      any[from] = true;
      last[from] = received[n].ids[i];
    }
  }
}

std::string name_kind(std::uint8_t kind) { return kind == kind_traffic ? "traffic" : "other"; }

}  // namespace

// A packet moved out of a slot (a ring entry, a channel's buffer) leaves a
// payload with no storage; a short payload moved in next must land in the
// slot's own inline bytes, not in memory allocated for it (an allocation
// there would be one per packet, inside a noexcept move, and end the
// program where memory runs out).
TEST(Packet, AShortPayloadMovedIntoAMovedFromSlotLiesInline) {
  Packet slot;
  slot.payload.assign(200, std::byte{7});
  const Packet taken = std::move(slot);
  ASSERT_EQ(taken.payload.size(), 200u);
  Packet next;
  next.payload.assign(inline_payload, std::byte{3});
  slot = std::move(next);
  ASSERT_EQ(slot.payload.size(), inline_payload);
  EXPECT_TRUE(std::all_of(slot.payload.begin(), slot.payload.end(), [](std::byte b) { return b == std::byte{3}; }));
  const auto* bytes = reinterpret_cast<const std::byte*>(&slot.payload);
  EXPECT_TRUE(slot.payload.data() >= bytes && slot.payload.data() < bytes + sizeof(Payload))
      << "the payload was allocated rather than kept inline";
}

TEST(Network, RandomStormWithBuffersOfOneDeliversEveryPacketOnce) {
  const std::vector<std::string> specs = {
      "hypercube:0", "hypercube:3", "hypercube:6", "hypercube:8", "mesh:1x1",  "mesh:3x5",
      "mesh:16x16",  "torus:1x1",   "torus:2x2",   "torus:5x3",   "torus:8x8", "torus:16x16",
      "ring:1",      "ring:2",      "ring:5",      "ring:64",     "ring:256",  "complete:1",
      "complete:2",  "complete:7",  "complete:32", "complete:256"};
  for (const auto& spec : specs) {
    SCOPED_TRACE(spec);
    const auto t = topology::parse_topology(spec);
    const std::size_t per_node = std::max<std::size_t>(8, 1000 / t.size());
    const Plan plan = random_plan(t.size(), per_node, 1234);
    for (const bool in_place : {false, true}) {
      NetworkOptions options;
      options.buffer_capacity = 1;
      options.forward_in_place = in_place;
      expect_each_delivered_once(t, plan, run_plan(t, plan, options));
    }
  }
}

// Routing in place changes who runs a router's step, not the step: the same
// links carry the same packets, every packet arrives once and in order, on
// one thread (every router in place) and two (in place within each, relays
// or shared channels between), with full and roomy buffers.
TEST(Network, RoutingInPlaceTakesTheSameLinksAsTheRoutersThemselves) {
  for (const char* spec : {"hypercube:4", "torus:5x3", "mesh:4x4", "ring:9", "complete:7"}) {
    const auto t = topology::parse_topology(spec);
    const Plan plan = random_plan(t.size(), 200, 99);
    for (const unsigned threads : {1u, 2u})
      for (const std::size_t buffers : {std::size_t{1}, std::size_t{4}})
        for (const bool relays : {false, true}) {
          SCOPED_TRACE(std::string(spec) + " threads " + std::to_string(threads) + " buffers " +
                       std::to_string(buffers) + (relays ? " relays" : ""));
          NetworkOptions options;
          options.buffer_capacity = buffers;
          options.relay_between_threads = relays;
          NetworkStats by_routers, in_place;
          expect_each_delivered_once(t, plan, run_plan(t, plan, options, &by_routers, 16, threads));
          options.forward_in_place = true;
          expect_each_delivered_once(t, plan, run_plan(t, plan, options, &in_place, 16, threads));
          ASSERT_EQ(in_place.links.size(), by_routers.links.size());
          for (std::size_t l = 0; l < in_place.links.size(); ++l) {
            EXPECT_EQ(in_place.links[l].packets, by_routers.links[l].packets) << l;
            EXPECT_EQ(in_place.links[l].bytes, by_routers.links[l].bytes) << l;
          }
          EXPECT_EQ(in_place.hops.total_hops, by_routers.hops.total_hops);
          std::uint64_t taken = 0, taken_by_routers = 0;
          for (const auto& r : in_place.routers) taken += r.in_place;
          for (const auto& r : by_routers.routers) taken_by_routers += r.in_place;
          EXPECT_EQ(taken_by_routers, 0u);
          EXPECT_GT(taken, 0u);
        }
  }
}

// Routers that put packets for another thread into the relays' rings
// themselves change who moves a packet, not where it goes: every packet
// arrives once and in order over the same links. They do so only with two
// credits or more left on the link (K = 1 leaves it all to the relays), and
// every packet one thread's relay side puts in a ring the other takes out.
TEST(Network, RoutersPutPacketsForOtherThreadsIntoTheRingsThemselves) {
  for (const char* spec : {"hypercube:4", "torus:5x3", "complete:7"}) {
    const auto t = topology::parse_topology(spec);
    const Plan plan = random_plan(t.size(), 200, 41);
    for (const unsigned threads : {2u, 3u})
      for (const std::size_t buffers : {std::size_t{1}, std::size_t{4}}) {
        SCOPED_TRACE(std::string(spec) + " threads " + std::to_string(threads) + " buffers " +
                     std::to_string(buffers));
        NetworkOptions options;
        options.buffer_capacity = buffers;
        options.relay_between_threads = true;
        options.forward_in_place = true;
        NetworkStats by_relays, by_routers;
        std::vector<nodes::RelayCounters> relays_alone, relays_and_routers;
        expect_each_delivered_once(t, plan, run_plan(t, plan, options, &by_relays, 16, threads, &relays_alone));
        options.send_across_in_place = true;
        expect_each_delivered_once(t, plan,
                                   run_plan(t, plan, options, &by_routers, 16, threads, &relays_and_routers));
        ASSERT_EQ(by_routers.links.size(), by_relays.links.size());
        for (std::size_t l = 0; l < by_routers.links.size(); ++l)
          EXPECT_EQ(by_routers.links[l].packets, by_relays.links[l].packets) << l;
        EXPECT_EQ(by_routers.hops.total_hops, by_relays.hops.total_hops);
        nodes::RelayCounters both, alone;
        for (const auto& r : relays_and_routers) both += r;
        for (const auto& r : relays_alone) alone += r;
        EXPECT_EQ(both.packets_sent, both.packets_received);
        EXPECT_EQ(both.packets_sent, alone.packets_sent);
        EXPECT_EQ(alone.sent_in_place, 0u);
        if (buffers == 1) {
          EXPECT_EQ(both.sent_in_place, 0u);
        } else {
          EXPECT_GT(both.sent_in_place, 0u);
          EXPECT_LE(both.sent_in_place, both.packets_sent);
        }
      }
  }
}

// Takes the packets of even id delivered to its node's port 0 in place,
// when the port holds nothing they would overtake.
class EvenTaker final : public PortReceiver {
 public:
  EvenTaker(csp::In<Packet> port, Received& received, std::function<void()> on_packet)
      : port_(std::move(port)), received_(received), on_packet_(std::move(on_packet)) {}
  bool takes_at_once(const Packet& p) const override { return p.id % 2 == 0 && !port_.ready_hint(); }
  void take(Packet& p) override {
    received_.ids.push_back(p.id);
    received_.sources.push_back(p.source);
    ++taken;
    on_packet_();
  }
  std::uint64_t taken = 0;

 private:
  csp::In<Packet> port_;
  Received& received_;
  std::function<void()> on_packet_;
};

// A port's receiver takes deliveries in place only where routers route in
// place, and then every packet still arrives once, as the routers'
// delivery count says. (A packet taken in place may overtake one already
// handed to the parked reader, so the order per sender is not asserted.)
TEST(Network, APortReceiverTakesDeliveriesInPlaceAndLosesNone) {
  for (const char* spec : {"hypercube:3", "torus:3x3"})
    for (const bool in_place : {false, true}) {
      SCOPED_TRACE(std::string(spec) + (in_place ? " in place" : " by the routers"));
      const auto t = topology::parse_topology(spec);
      const Plan plan = random_plan(t.size(), 100, 7);
      csp::Runtime runtime(1);
      NetworkOptions options;
      options.buffer_capacity = 2;
      options.forward_in_place = in_place;
      Network net(runtime, t, options);
      const std::vector<std::size_t> expected = packets_to_each(plan);
      std::vector<Received> received(t.size());
      std::size_t unfinished = t.size();
      auto done_with = [&](NodeId n) {
        if (received[n].ids.size() == expected[n] && --unfinished == 0) net.shutdown();
      };
      std::vector<std::unique_ptr<EvenTaker>> takers;
      std::uint64_t next_id = 0;
      for (NodeId n = 0; n < t.size(); ++n) {
        takers.push_back(std::make_unique<EvenTaker>(net.port(n), received[n], [&done_with, n] { done_with(n); }));
        EXPECT_EQ(net.receive_in_place(n, 0, *takers.back()), in_place);
        std::vector<Packet> packets = node_packets(plan, n, next_id, 0);
        runtime.spawn("send " + std::to_string(n), 0, [out = net.in_place_injector(n), packets]() mutable {
          for (auto& p : packets) out.write(std::move(p));
        });
        runtime.spawn("receive " + std::to_string(n), 0, [&, n, in = net.port(n)]() mutable {
          try {
            while (received[n].ids.size() < expected[n]) {
              Packet p = in.read();
              received[n].ids.push_back(p.id);
              received[n].sources.push_back(p.source);
              done_with(n);
            }
          } catch (const csp::Poisoned&) {  // the last packets were taken in place
          }
        });
      }
      runtime.run();
      std::vector<int> seen(next_id, 0);
      for (NodeId n = 0; n < t.size(); ++n) {
        EXPECT_EQ(received[n].ids.size(), expected[n]) << n;
        for (std::uint64_t id : received[n].ids) ++seen.at(id);
      }
      EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(next_id));
      std::uint64_t taken = 0, delivered = 0;
      for (const auto& taker : takers) taken += taker->taken;
      for (const auto& r : net.stats().routers) delivered += r.delivered;
      EXPECT_EQ(delivered, next_id);
      if (in_place)
        EXPECT_GT(taken, 0u);
      else
        EXPECT_EQ(taken, 0u);
    }
}

TEST(Network, AllToAllMeanHopsEqualsAnalyticAverageDistance) {
  for (const auto& spec : {"hypercube:6", "mesh:8x8", "torus:8x8", "torus:5x3", "ring:64",
                           "ring:9", "complete:16", "mesh:7x3"}) {
    SCOPED_TRACE(spec);
    const auto t = topology::parse_topology(spec);
    const Plan plan = all_to_all_plan(t.size());
    NetworkStats stats;
    const auto received = run_plan(t, plan, NetworkOptions{}, &stats);
    expect_each_delivered_once(t, plan, received);
    std::uint64_t hops = 0;
    for (const auto& r : received) hops += r.hops;
    EXPECT_EQ(hops, t.total_distance()) << spec;
    EXPECT_EQ(stats.hops.total_hops, t.total_distance()) << spec;
    EXPECT_DOUBLE_EQ(stats.hops.mean(), t.average_distance()) << spec;
    EXPECT_EQ(stats.hops.max_hops, t.diameter()) << spec;
  }
}

TEST(Network, LinkCountersAddUpToTheHopsTaken) {
  const auto t = topology::parse_topology("torus:4x4");
  const Plan plan = all_to_all_plan(t.size());
  NetworkStats stats;
  run_plan(t, plan, NetworkOptions{}, &stats, 100);
  std::uint64_t packets = 0, bytes = 0, forwarded = 0;
  for (const auto& l : stats.links) {
    packets += l.packets;
    bytes += l.bytes;
  }
  for (const auto& r : stats.routers) forwarded += r.forwarded;
  EXPECT_EQ(packets, t.total_distance());
  EXPECT_EQ(bytes, 100 * t.total_distance());
  EXPECT_EQ(forwarded, t.total_distance());
  EXPECT_EQ(stats.hops_by_kind.at(kind_traffic).packets, 16u * 15u);
}

TEST(Network, TracedRoutesFollowLinksHopByHop) {
  const auto t = topology::parse_topology("hypercube:4");
  NetworkOptions options;
  options.trace_routes = 10;
  options.forward_in_place = true;  // a route taken in place is traced as one the routers took
  NetworkStats stats;
  run_plan(t, all_to_all_plan(t.size()), options, &stats, 16, 1);
  ASSERT_EQ(stats.routes.size(), 10u);
  for (const auto& r : stats.routes) {
    ASSERT_GE(r.route.size(), 2u);
    for (std::size_t i = 1; i < r.route.size(); ++i)
      EXPECT_EQ(t.distance(r.route[i - 1], r.route[i]), 1u);
  }
  // Each goes the topology's own way: e-cube, lowest dimension first.
  for (const auto& r : stats.routes)
    for (std::size_t i = 1; i < r.route.size(); ++i)
      EXPECT_EQ(r.route[i], t.neighbour(r.route[i - 1], t.next_hop(r.route[i - 1], r.route.back()).port));
  // "traffic 6: 0 → 1 → 3 → 7 (3 hops)" for a packet from node 0 to node 7.
  const nodes::RouteRecord zero_to_seven{6, kind_traffic, {0, 1, 3, 7}};
  EXPECT_EQ(format_route(zero_to_seven, name_kind), "traffic 6: 0 \u2192 1 \u2192 3 \u2192 7 (3 hops)");
  const std::string summary = format_summary(stats, t, name_kind);
  EXPECT_NE(summary.find("busiest link"), std::string::npos) << summary;
  EXPECT_NE(summary.find("traffic"), std::string::npos) << summary;
}

TEST(Network, LinkModelStillDeliversEverything) {
  const auto t = topology::parse_topology("ring:6");
  NetworkOptions options;
  options.link.latency = std::chrono::microseconds(5);
  options.link.bytes_per_second = 2.8e6;
  const Plan plan = random_plan(t.size(), 20, 7);
  expect_each_delivered_once(t, plan, run_plan(t, plan, options));
}

TEST(Network, ShutdownOfAnIdleNetworkEndsEveryProcess) {
  csp::Runtime runtime(2);
  Network net(runtime, topology::parse_topology("torus:4x4"), NetworkOptions{});
  bool reader_poisoned = false;
  runtime.spawn("reader", 0, [&, in = net.port(5)]() mutable {
    try {
      in.read();
    } catch (const csp::Poisoned&) {
      reader_poisoned = true;
    }
  });
  runtime.spawn("stopper", 1, [&] { net.shutdown(); });
  EXPECT_NO_THROW(runtime.run());
  EXPECT_TRUE(reader_poisoned);
}

TEST(Network, BlockPlacementKeepsNeighbourRangesTogether) {
  EXPECT_EQ(Network::block_placement(0, 64, 2), 0u);
  EXPECT_EQ(Network::block_placement(31, 64, 2), 0u);
  EXPECT_EQ(Network::block_placement(32, 64, 2), 1u);
  EXPECT_EQ(Network::block_placement(63, 64, 2), 1u);
  EXPECT_EQ(Network::block_placement(0, 1, 2), 0u);
}
