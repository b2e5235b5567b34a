// Routing: every pair reached by a minimal path, deterministic tie-breaks.
#include <gtest/gtest.h>

#include "topology/topology.hpp"
#include "topology_test_util.hpp"

using namespace topology;
using topology::testing::sample_topologies;

// Routing depends only on (current, destination), so a route is minimal from
// every source iff every single hop brings the packet one step closer; that
// checks all N^2 pairs with N^2 look-ups even on 1024 nodes.
TEST(Routing, EveryHopOfEveryPairIsMinimal) {
  for (const Topology& t : sample_topologies(true)) {
    for (NodeId at = 0; at < t.size(); ++at) {
      for (NodeId dst = 0; dst < t.size(); ++dst) {
        if (at == dst) continue;
        const Hop hop = t.next_hop(at, dst);
        ASSERT_LT(hop.port, t.degree(at)) << t.spec();
        ASSERT_LT(hop.buffer_class, t.buffer_classes()) << t.spec();
        const NodeId next = t.neighbour(at, hop.port);
        ASSERT_EQ(t.distance(next, dst) + 1, t.distance(at, dst))
            << t.spec() << " at " << at << " towards " << dst;
      }
    }
  }
}

TEST(Routing, FollowingHopsReachesDestinationInDistanceSteps) {
  for (const Topology& t : sample_topologies(false)) {
    for (NodeId src = 0; src < t.size(); ++src) {
      for (NodeId dst = 0; dst < t.size(); ++dst) {
        NodeId at = src;
        unsigned hops = 0;
        while (at != dst && hops <= t.diameter()) {
          at = t.neighbour(at, t.next_hop(at, dst).port);
          ++hops;
        }
        ASSERT_EQ(at, dst) << t.spec() << " " << src << "->" << dst;
        ASSERT_EQ(hops, t.distance(src, dst)) << t.spec();
      }
    }
  }
}

TEST(Routing, HypercubeCorrectsLowestBitFirst) {
  const auto t = Topology::hypercube(4);
  EXPECT_EQ(t.next_hop(0b0101, 0b1110).port, 0u);
  EXPECT_EQ(t.next_hop(0b0100, 0b1110).port, 1u);
  EXPECT_EQ(t.next_hop(0b0110, 0b1110).port, 3u);
}

TEST(Routing, MeshGoesAlongXBeforeY) {
  const auto t = Topology::mesh(4, 4);
  // From (0,0) to (2,3): first hop must stay in row 0.
  EXPECT_EQ(t.neighbour(0, t.next_hop(0, 14).port), 1u);
  // From (2,0) to (2,3): x done, go down.
  EXPECT_EQ(t.neighbour(2, t.next_hop(2, 14).port), 6u);
}

TEST(Routing, RingAndTorusTiesGoForward) {
  const auto ring = Topology::ring(8);
  EXPECT_EQ(ring.neighbour(2, ring.next_hop(2, 6).port), 3u);  // 4 either way: +1
  EXPECT_EQ(ring.neighbour(6, ring.next_hop(6, 2).port), 7u);
  EXPECT_EQ(ring.neighbour(1, ring.next_hop(1, 7).port), 0u);  // shorter backwards
  const auto torus = Topology::torus(4, 4);
  EXPECT_EQ(torus.neighbour(0, torus.next_hop(0, 2).port), 1u);
  EXPECT_EQ(torus.neighbour(3, torus.next_hop(3, 0).port), 0u);  // wraps
}

TEST(Routing, DatelineClassChangesAfterTheWrapLink) {
  const auto ring = Topology::ring(8);
  // 6 -> 1 goes 6,7,0,1: class 0 until the wrap, class 1 after it.
  EXPECT_EQ(ring.next_hop(6, 1).buffer_class, 0);
  EXPECT_EQ(ring.next_hop(7, 1).buffer_class, 0);
  EXPECT_EQ(ring.next_hop(0, 1).buffer_class, 1);
  EXPECT_EQ(ring.naive_next_hop(6, 1).buffer_class, 0);
  EXPECT_EQ(ring.buffer_classes(), 2u);
  EXPECT_EQ(Topology::hypercube(3).buffer_classes(), 1u);
}

TEST(Routing, NextHopToSelfIsALogicError) {
  EXPECT_THROW(Topology::ring(4).next_hop(2, 2), std::logic_error);
}
