// Graph structure: ports, symmetry, closed-form distances against BFS.
#include "topology/topology.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "topology_test_util.hpp"

using namespace topology;
using topology::testing::bfs_distances;
using topology::testing::sample_topologies;

TEST(Topology, LinksAreSymmetricAndPortsDense) {
  for (const Topology& t : sample_topologies(false)) {
    for (NodeId n = 0; n < t.size(); ++n) {
      const auto nbs = t.neighbours(n);
      ASSERT_EQ(nbs.size(), t.degree(n)) << t.spec();
      for (Port p = 0; p < nbs.size(); ++p) {
        const NodeId m = nbs[p];
        ASSERT_NE(m, n) << t.spec() << " self link at " << n;
        ASSERT_LT(m, t.size());
        ASSERT_EQ(t.neighbour(n, p), m);
        ASSERT_EQ(t.port_to(n, m), p) << t.spec();
        const auto back = t.neighbours(m);
        ASSERT_EQ(std::count(back.begin(), back.end(), n), 1) << t.spec() << " " << n << "-" << m;
      }
    }
  }
}

TEST(Topology, DegreesMatchTheKind) {
  EXPECT_EQ(Topology::hypercube(6).degree(13), 6u);
  EXPECT_EQ(Topology::mesh(8, 8).degree(0), 2u);
  EXPECT_EQ(Topology::mesh(8, 8).degree(9), 4u);
  EXPECT_EQ(Topology::torus(4, 4).degree(0), 4u);
  EXPECT_EQ(Topology::torus(2, 2).degree(0), 2u);  // extent 2: one link per dimension
  EXPECT_EQ(Topology::ring(64).degree(5), 2u);
  EXPECT_EQ(Topology::ring(2).degree(0), 1u);
  EXPECT_EQ(Topology::complete(16).degree(3), 15u);
  for (auto t : {Topology::hypercube(0), Topology::mesh(1, 1), Topology::torus(1, 1),
                 Topology::ring(1), Topology::complete(1)}) {
    EXPECT_EQ(t.size(), 1u) << t.spec();
    EXPECT_EQ(t.degree(0), 0u) << t.spec();
    EXPECT_EQ(t.diameter(), 0u) << t.spec();
    EXPECT_EQ(t.average_distance(), 0.0) << t.spec();
  }
}

TEST(Topology, DistancesAgreeWithBreadthFirstSearch) {
  for (const Topology& t : sample_topologies(false)) {
    std::uint64_t total = 0;
    unsigned diameter = 0;
    for (NodeId a = 0; a < t.size(); ++a) {
      const auto dist = bfs_distances(t, a);
      for (NodeId b = 0; b < t.size(); ++b) {
        ASSERT_EQ(t.distance(a, b), dist[b]) << t.spec() << " " << a << "->" << b;
        total += dist[b];
        diameter = std::max(diameter, dist[b]);
      }
    }
    EXPECT_EQ(t.total_distance(), total) << t.spec();
    EXPECT_EQ(t.diameter(), diameter) << t.spec();
  }
}

TEST(Topology, AverageDistanceIsExactForKnownMachines) {
  // 6-cube: 6 * 32 / 63 over distinct pairs.
  EXPECT_DOUBLE_EQ(Topology::hypercube(6).average_distance(), 192.0 / 63.0);
  EXPECT_EQ(Topology::hypercube(6).total_distance(), 64u * 192u);
  // 8x8 mesh: 2 * 8 * (8*63/3) ... summed over ordered pairs = 2 * 64 * 168.
  EXPECT_EQ(Topology::mesh(8, 8).total_distance(), 2u * 64u * 168u);
  EXPECT_EQ(Topology::torus(4, 4).total_distance(), 2u * 16u * 16u);
  EXPECT_EQ(Topology::ring(64).total_distance(), 64u * 1024u);
  EXPECT_DOUBLE_EQ(Topology::complete(16).average_distance(), 1.0);
}

TEST(Topology, CoordinatesIdentifyNodes) {
  const auto cube = Topology::hypercube(3);
  EXPECT_EQ(cube.coordinates(6), (std::vector<unsigned>{0, 1, 1}));
  const auto mesh = Topology::mesh(8, 4);
  EXPECT_EQ(mesh.coordinates(19), (std::vector<unsigned>{3, 2}));
  EXPECT_EQ(Topology::ring(9).coordinates(7), (std::vector<unsigned>{7}));
}

TEST(Topology, SpecIsCanonical) {
  EXPECT_EQ(Topology::hypercube(6).spec(), "hypercube:6");
  EXPECT_EQ(Topology::mesh(8, 4).spec(), "mesh:8x4");
  EXPECT_EQ(Topology::torus(4, 4).spec(), "torus:4x4");
  EXPECT_EQ(Topology::ring(64).spec(), "ring:64");
  EXPECT_EQ(Topology::complete(16).spec(), "complete:16");
}
