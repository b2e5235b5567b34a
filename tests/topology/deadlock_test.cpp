// Channel dependency analysis: naive ring/torus routing has a cycle, the
// dateline buffer classes remove it; e-cube, XY and direct are acyclic.
#include "topology/deadlock.hpp"

#include <gtest/gtest.h>

#include "topology_test_util.hpp"

using namespace topology;

namespace {

void expect_closed_cycle(const Topology& t, const DependencyAnalysis& a) {
  ASSERT_FALSE(a.acyclic) << t.spec();
  ASSERT_GE(a.cycle.size(), 2u) << t.spec();
  for (std::size_t i = 0; i < a.cycle.size(); ++i) {
    const auto& c = a.cycle[i];
    const auto& next = a.cycle[(i + 1) % a.cycle.size()];
    EXPECT_EQ(t.neighbour(c.from, c.port), c.to);
    EXPECT_EQ(c.to, next.from) << t.spec() << ": " << a.describe();
  }
}

}  // namespace

TEST(Deadlock, NaiveRingRoutingHasACycle) {
  for (unsigned n : {4u, 5u, 8u, 16u, 65u}) {
    const auto t = Topology::ring(n);
    expect_closed_cycle(t, analyse_naive(t));
  }
}

TEST(Deadlock, NaiveTorusRoutingHasACycle) {
  for (auto [w, h] : std::vector<std::pair<unsigned, unsigned>>{{4, 4}, {5, 3}, {8, 8}, {1, 6}}) {
    const auto t = Topology::torus(w, h);
    expect_closed_cycle(t, analyse_naive(t));
  }
}

TEST(Deadlock, DatelineClassesMakeEveryTopologyAcyclic) {
  for (const Topology& t : topology::testing::sample_topologies(false)) {
    const auto a = analyse_deadlock_free(t);
    EXPECT_TRUE(a.acyclic) << t.spec() << ": " << a.describe();
    EXPECT_EQ(a.channels, [&] {
      std::size_t links = 0;
      for (NodeId n = 0; n < t.size(); ++n) links += t.degree(n);
      return links * t.buffer_classes();
    }()) << t.spec();
  }
}

TEST(Deadlock, LargeMachinesAreAcyclic) {
  for (const auto& t : {Topology::hypercube(10), Topology::torus(32, 32), Topology::ring(1024),
                        Topology::mesh(32, 32)})
    EXPECT_TRUE(analyse_deadlock_free(t).acyclic) << t.spec();
}

TEST(Deadlock, SingleClassRoutingsAreAcyclicEvenNaively) {
  for (const auto& t : {Topology::hypercube(6), Topology::mesh(8, 8), Topology::complete(16),
                        Topology::ring(3)}) {
    EXPECT_TRUE(analyse_naive(t).acyclic) << t.spec();
  }
}

TEST(Deadlock, DescribeNamesTheCycle) {
  const auto a = analyse_naive(Topology::ring(4));
  EXPECT_NE(a.describe().find("cycle of 4 channels"), std::string::npos) << a.describe();
  EXPECT_NE(analyse_deadlock_free(Topology::ring(4)).describe().find("acyclic"),
            std::string::npos);
}
