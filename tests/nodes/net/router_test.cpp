// One router driven through its own channels by a test process: injected
// packets leave by the link of the routing function with their source
// stamped and no hops, packets from a link are delivered to their port or
// passed on with one hop more, and the counters say which. On a 2-cube
// node 0's ports are 0 (to node 1) and 1 (to node 2), one buffer class.
#include "nodes/net/router.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "csp/csp.hpp"

namespace {

using nodes::NodeId;
using nodes::Packet;

constexpr std::size_t delivery_ports = 3;

// The router of node 0 of a 2-cube, and the other ends of its channels.
struct ScriptedRouter {
  topology::Topology cube = topology::Topology::hypercube(2);
  std::vector<csp::Channel<Packet>> inputs, outputs;  // outputs: the link queues, then one per port
  csp::Channel<Packet> injection{"injection", 4};
  nodes::RouterCounters counters;

  ScriptedRouter() {
    const unsigned links = cube.degree(0) * cube.buffer_classes();
    for (unsigned q = 0; q < links; ++q) inputs.emplace_back("link in " + std::to_string(q), 4);
    for (unsigned q = 0; q < links + delivery_ports; ++q) outputs.emplace_back("out " + std::to_string(q), 4);
  }

  nodes::Router router() {
    nodes::RouterEnds ends;
    for (auto& c : inputs) ends.inputs.push_back(c.reader());
    ends.injections.push_back(injection.reader());
    for (auto& c : outputs) ends.outputs.push_back(c.writer());
    return nodes::Router(cube, 0, std::move(ends), {}, counters);
  }
  csp::In<Packet> link_queue(unsigned port) { return outputs[port * cube.buffer_classes()].reader(); }
  csp::In<Packet> delivery(std::size_t port) { return outputs[inputs.size() + port].reader(); }
};

Packet to(NodeId destination, std::uint16_t port, std::uint64_t id) {
  Packet p;
  p.destination = destination;
  p.port = port;
  p.id = id;
  p.kind = nodes::kind_traffic;
  return p;
}

TEST(Router, ForwardsDeliversAndCountsHops) {
  ScriptedRouter s;
  csp::Runtime runtime(1);
  runtime.spawn("router", 0, [&s] { s.router().run(); });
  runtime.spawn("script", 0, [&s] {
    // Injected for node 3: one hop to node 1 (port 0) first, the source
    // stamped, whatever the sender wrote into source and hops.
    Packet injected = to(3, 1, 7);
    injected.source = 2;
    injected.hops = 5;
    s.injection.writer().write(injected);
    const Packet out = s.link_queue(s.cube.next_hop(0, 3).port).read();
    EXPECT_EQ(out.id, 7u);
    EXPECT_EQ(out.source, 0u);
    EXPECT_EQ(out.hops, 0u);
    EXPECT_EQ(s.cube.neighbour(0, s.cube.next_hop(0, 3).port), 1u);

    // From node 1 (port 0) for node 0's port 2: delivered there, one hop more.
    Packet arrived = to(0, 2, 8);
    arrived.source = 1;
    arrived.hops = 1;
    s.inputs[0].writer().write(arrived);
    const Packet delivered = s.delivery(2).read();
    EXPECT_EQ(delivered.id, 8u);
    EXPECT_EQ(delivered.hops, 2u);

    // From node 1 for node 2: passed on by port 1, one hop more.
    Packet transit = to(2, 0, 9);
    transit.source = 1;
    transit.hops = 1;
    s.inputs[0].writer().write(transit);
    const Packet passed = s.link_queue(1).read();
    EXPECT_EQ(passed.id, 9u);
    EXPECT_EQ(passed.hops, 2u);
    EXPECT_EQ(passed.source, 1u);
    s.injection.poison();  // ends the router, as the network's shutdown does
  });
  runtime.run();
  EXPECT_EQ(s.counters.injected, 1u);
  EXPECT_EQ(s.counters.forwarded, 2u);
  EXPECT_EQ(s.counters.delivered, 1u);
  EXPECT_EQ(s.counters.hops.packets, 1u);
  EXPECT_EQ(s.counters.hops.total_hops, 2u);
  EXPECT_EQ(s.counters.hops_by_kind[nodes::kind_traffic].packets, 1u);
  EXPECT_EQ(s.counters.sent[0].packets, 1u);  // to node 1
  EXPECT_EQ(s.counters.sent[1].packets, 1u);  // to node 2
  EXPECT_EQ(s.counters.sent[s.inputs.size() + 2].packets, 1u);
}

// A full output holds the packet back; it goes out, in order, once the
// queue has room, and the input it came from is read again only then.
TEST(Router, HoldsAPacketBackUntilItsQueueHasRoom) {
  ScriptedRouter s;
  csp::Runtime runtime(1);
  runtime.spawn("router", 0, [&s] { s.router().run(); });
  runtime.spawn("script", 0, [&s] {
    for (std::uint64_t id = 0; id < 6; ++id) s.injection.writer().write(to(0, 1, id));
    while (s.counters.peak_pending == 0) csp::yield();
    EXPECT_EQ(s.counters.delivered, 4u);  // the delivery queue holds 4
    for (std::uint64_t id = 0; id < 6; ++id) EXPECT_EQ(s.delivery(1).read().id, id);
    s.injection.poison();
  });
  runtime.run();
  EXPECT_EQ(s.counters.delivered, 6u);
  EXPECT_EQ(s.counters.peak_pending, 1u);
}

TEST(Router, RefusesAPacketForAPortThatDoesNotExist) {
  ScriptedRouter s;
  csp::Runtime runtime(1);
  runtime.spawn("router", 0, [&s] { s.router().run(); });
  runtime.spawn("script", 0, [&s] { s.injection.writer().write(to(1, delivery_ports, 3)); });
  try {
    runtime.run();
    ADD_FAILURE() << "no error";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("port 3, which does not exist"), std::string::npos) << e.what();
  }
}

}  // namespace
