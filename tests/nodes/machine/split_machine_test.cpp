// The machine split over ranks, each a thread of this process over the
// in-process transport (the same seam MPI fills across processes): the
// image equals the one-process machine's for every topology, rank count,
// schedule, cache and thread count; statistics equal it where the schedule
// is deterministic; what crossed the wire equals the cut links' counters;
// no rank holds more scene than its nodes' pages and caches; a failure on
// any rank, or bad set-up on rank 0, ends every rank with one line.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "nodes/machine/machine.hpp"
#include "tests/nodes/machine/test_database.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"

namespace {

using nodes::MachineOptions;
using nodes::Schedule;

using test::make_db;

bool same_bits(const tracer::Image& a, const tracer::Image& b) {
  return a.pixels().size() == b.pixels().size() &&
         std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(tracer::Color)) == 0;
}

// Runs every rank of a group: rank 0 on this thread with the database, the
// others on threads of their own. Each rank's exception is kept.
struct SplitRun {
  std::optional<nodes::MachineResult> result;
  std::vector<std::exception_ptr> errors;  // per rank
};

SplitRun run_split(tracer::Database db, const MachineOptions& options, int ranks,
                   std::function<nodes::Transport&(nodes::Transport&)> wrap = {}) {
  nodes::LocalTransportGroup group(ranks);
  SplitRun run;
  run.errors.resize(static_cast<std::size_t>(ranks));
  std::vector<std::thread> threads;
  const auto transport = [&](int r) -> nodes::Transport& { return wrap ? wrap(group.rank(r)) : group.rank(r); };
  for (int r = 1; r < ranks; ++r)
    threads.emplace_back([&, r] {
      try {
        EXPECT_FALSE(nodes::run_machine_rank(std::nullopt, options, transport(r)).has_value());
      } catch (...) {
        run.errors[static_cast<std::size_t>(r)] = std::current_exception();
      }
    });
  try {
    run.result = nodes::run_machine_rank(std::move(db), options, transport(0));
  } catch (...) {
    run.errors[0] = std::current_exception();
  }
  for (auto& t : threads) t.join();
  return run;
}

std::string what(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  }
}

struct Case {
  std::string topology;
  int ranks;
  Schedule schedule = Schedule::dynamic;
  std::uint32_t cache_pages = 2;  // 0: the whole database
  unsigned threads = 1;
  std::string scene = "teapot:2";
  int size = 20;
  std::uint32_t page_size = 1024;
  int workers = 1;
};

std::string describe(const Case& c) {
  return c.topology + " ranks=" + std::to_string(c.ranks) + " " + nodes::schedule_name(c.schedule) +
         " cache=" + std::to_string(c.cache_pages) + " threads=" + std::to_string(c.threads) + " " + c.scene;
}

MachineOptions options_for(const Case& c, const tracer::Database& db) {
  MachineOptions o;
  o.topology = topology::parse_topology(c.topology);
  o.threads.count = c.threads;
  o.cache.pages = c.cache_pages ? c.cache_pages : db.header.page_count;
  o.farming.schedule = c.schedule;
  o.farming.grain = 4;
  o.shape.workers_per_node = c.workers;
  return o;
}

// Packets and payload bytes the routers of `rank`'s nodes put on links to
// other ranks' nodes.
std::pair<std::uint64_t, std::uint64_t> cut_traffic(const nodes::MachineReport& r, const nodes::RankPlan& plan,
                                                    int rank) {
  std::uint64_t packets = 0, bytes = 0;
  for (const auto& link : r.network.links)
    if (plan.rank_of(link.from) == rank && plan.rank_of(link.to) != rank) {
      packets += link.packets;
      bytes += link.bytes;
    }
  return {packets, bytes};
}

void check_case(const Case& c) {
  SCOPED_TRACE(describe(c));
  auto db = make_db(c.scene, c.page_size, c.size);
  const MachineOptions options = options_for(c, db);
  const auto whole = nodes::run_machine(make_db(c.scene, c.page_size, c.size), options);
  const auto split = run_split(std::move(db), options, c.ranks);
  for (int r = 0; r < c.ranks; ++r)
    ASSERT_FALSE(split.errors[static_cast<std::size_t>(r)]) << "rank " << r << ": "
                                                            << what(split.errors[static_cast<std::size_t>(r)]);
  ASSERT_TRUE(split.result);
  const nodes::MachineReport& s = split.result->report;
  EXPECT_TRUE(same_bits(split.result->image, whole.image));

  // The machine's invariants, whatever the schedule.
  EXPECT_EQ(s.items_computed(), s.items);
  EXPECT_EQ(s.collected, s.items);
  EXPECT_EQ(s.farmer.items, s.items);
  EXPECT_EQ(s.svm().misses, s.served().pages_served);
  std::uint64_t tiles = 0;
  for (const auto& n : s.per_node) tiles += n.work.tiles;
  EXPECT_EQ(tiles, s.farmer.results);

  // Where the schedule fixes who computes what, every count is the same.
  if (c.schedule == Schedule::static_split) {
    EXPECT_EQ(s.rays().rays(), whole.report.rays().rays());
    ASSERT_EQ(s.per_node.size(), whole.report.per_node.size());
    for (std::size_t n = 0; n < s.per_node.size(); ++n) {
      EXPECT_EQ(s.per_node[n].work.items, whole.report.per_node[n].work.items) << "node " << n;
      EXPECT_EQ(s.per_node[n].svm.misses, whole.report.per_node[n].svm.misses) << "node " << n;
      EXPECT_EQ(s.per_node[n].svm.own_hits, whole.report.per_node[n].svm.own_hits) << "node " << n;
      EXPECT_EQ(s.per_node[n].served.pages_served, whole.report.per_node[n].served.pages_served) << "node " << n;
    }
    ASSERT_EQ(s.network.links.size(), whole.report.network.links.size());
    for (std::size_t l = 0; l < s.network.links.size(); ++l)
      EXPECT_EQ(s.network.links[l].bytes, whole.report.network.links[l].bytes) << "link " << l;
    EXPECT_EQ(s.network.hops.packets, whole.report.network.hops.packets);
    EXPECT_EQ(s.network.hops.total_hops, whole.report.network.hops.total_hops);
  }

  // The ranks, their share of the nodes, and what crossed the wire.
  const auto topology = topology::parse_topology(c.topology, std::nullopt);
  const nodes::RankPlan plan(topology, c.ranks);
  ASSERT_EQ(s.ranks.size(), static_cast<std::size_t>(c.ranks));
  EXPECT_EQ(s.cut_links, plan.cut_links());
  std::uint64_t sent = 0, received = 0;
  for (const auto& k : s.ranks) {
    EXPECT_EQ(k.first_node, plan.first(k.rank));
    EXPECT_EQ(k.node_count, plan.count(k.rank));
    const auto [packets, bytes] = cut_traffic(s, plan, k.rank);
    EXPECT_EQ(k.bridge.packets_sent, packets) << "rank " << k.rank;
    EXPECT_EQ(k.bridge.bytes_sent, bytes) << "rank " << k.rank;
    sent += k.bridge.packets_sent;
    received += k.bridge.packets_received;
    // A rank holds its own nodes' pages and caches, never the database.
    std::uint64_t bound = 0;
    for (auto n = k.first_node; n < k.first_node + k.node_count; ++n)
      bound += s.per_node[n].own_bytes + std::uint64_t{s.per_node[n].cache_capacity} * s.page_size;
    EXPECT_LE(k.peak_scene_bytes, bound) << "rank " << k.rank;
  }
  EXPECT_EQ(sent, received);
  if (plan.cut_links() > 0) {
    EXPECT_GT(sent, 0u);
  }
}

TEST(SplitMachine, ImageAndCountsMatchTheOneProcessMachine) {
  const std::vector<Case> cases{
      {"hypercube:4", 1},
      {"hypercube:4", 2, Schedule::static_split},
      {"hypercube:4", 3},
      {"hypercube:4", 4, Schedule::affinity},
      {"hypercube:6", 2, Schedule::static_split, 1},
      {"hypercube:6", 4, Schedule::dynamic, 0, 2},
      {"mesh:4x4", 3, Schedule::static_split},
      {"torus:4x4", 2, Schedule::affinity, 1, 2},
      {"ring:16", 3, Schedule::dynamic, 1},
      {"ring:16", 4, Schedule::static_split, 0},
      {"complete:8", 4, Schedule::affinity},
      {"complete:8", 8, Schedule::static_split, 1},
      {"hypercube:3", 2, Schedule::dynamic, 2, 2, "balls:1", 16, 256, 2},
  };
  for (const auto& c : cases) check_case(c);
}

// The paper's point, across processes: a scene far larger than what any
// rank holds (tetra:5 is 1024 triangles, 64 nodes on 4 ranks).
TEST(SplitMachine, NoRankHoldsMoreThanItsNodesPagesAndCaches) {
  auto db = make_db("tetra:5", 256, 16);
  const std::uint64_t database = db.header.bytes();
  MachineOptions options = options_for({"hypercube:6", 4}, db);
  options.cache.pages = 4;
  const auto run = run_split(std::move(db), options, 4);
  ASSERT_TRUE(run.result) << what(run.errors[0]);
  const auto& r = run.result->report;
  ASSERT_EQ(r.ranks.size(), 4u);
  for (const auto& k : r.ranks) {
    std::uint64_t own = 0, caches = 0;
    for (auto n = k.first_node; n < k.first_node + k.node_count; ++n) {
      own += r.per_node[n].own_bytes;
      caches += std::uint64_t{r.per_node[n].cache_capacity} * r.page_size;
    }
    EXPECT_LE(k.peak_scene_bytes, own + caches) << "rank " << k.rank;
    EXPECT_LT(k.peak_scene_bytes, database / 2) << "rank " << k.rank;
  }
}

TEST(SplitMachine, TracedRoutesThatCrossRanksHaveHopsEqualToDistance) {
  auto db = make_db("teapot:2", 1024, 16);
  MachineOptions options = options_for({"hypercube:4", 4}, db);
  options.observe.trace_routes = 200;
  const auto run = run_split(std::move(db), options, 4);
  ASSERT_TRUE(run.result) << what(run.errors[0]);
  const auto& routes = run.result->report.network.routes;
  EXPECT_EQ(routes.size(), 200u);
  const auto topology = topology::parse_topology("hypercube:4", std::nullopt);
  const nodes::RankPlan plan(topology, 4);
  std::size_t crossing = 0;
  for (const auto& r : routes) {
    ASSERT_GE(r.route.size(), 1u);
    EXPECT_EQ(r.route.size() - 1, topology.distance(r.route.front(), r.route.back()));
    if (plan.rank_of(r.route.front()) != plan.rank_of(r.route.back())) ++crossing;
  }
  EXPECT_GT(crossing, 0u);
}

// A replay recorded over 2 and 3 ranks: rank 0 gathers every rank's logs
// onto its clock, and under the static schedule (which fixes who computes
// what) the recording ends with the one-process run's counters: packets
// and hops by kind, waits and serves by node, tiles; each node's rank is
// named, and packets that crossed between ranks are among those recorded.
TEST(SplitMachine, AReplayRecordedOverRanksCountsWhatOneProcessCounts) {
  for (const int ranks : {2, 3}) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks");
    auto db = make_db("teapot:2", 1024, 16);
    MachineOptions options = options_for({"hypercube:3", ranks, Schedule::static_split}, db);
    options.observe.record = true;
    options.observe.record_packets = 1u << 20;
    const auto whole = nodes::run_machine(make_db("teapot:2", 1024, 16), options);
    const auto run = run_split(std::move(db), options, ranks);
    for (int r = 0; r < ranks; ++r)
      ASSERT_FALSE(run.errors[static_cast<std::size_t>(r)]) << what(run.errors[static_cast<std::size_t>(r)]);
    ASSERT_TRUE(run.result);
    ASSERT_TRUE(run.result->report.recording);
    const nodes::Recording& split = *run.result->report.recording;
    const nodes::Recording& one = *whole.report.recording;
    EXPECT_EQ(split.unrecorded_packets, 0u);
    EXPECT_EQ(split.packets.size(), one.packets.size());
    EXPECT_EQ(split.packets.size(), run.result->report.network.hops.packets);
    EXPECT_EQ(split.recorded_hops(), one.recorded_hops());
    EXPECT_EQ(split.max_packets, options.observe.record_packets);
    const auto by_kind = [](const nodes::Recording& r) {
      std::vector<std::uint64_t> k(256, 0);
      for (const auto& p : r.packets) ++k[p.kind];
      return k;
    };
    EXPECT_EQ(by_kind(split), by_kind(one));
    const auto topology = topology::parse_topology("hypercube:3", std::nullopt);
    const nodes::RankPlan plan(topology, ranks);
    ASSERT_EQ(split.node_rank.size(), topology.size());
    ASSERT_EQ(split.nodes.size(), one.nodes.size());
    for (std::size_t n = 0; n < split.nodes.size(); ++n) {
      EXPECT_EQ(split.node_rank[n], plan.rank_of(static_cast<nodes::NodeId>(n))) << "node " << n;
      EXPECT_EQ(split.nodes[n].fetches.size(), one.nodes[n].fetches.size()) << "node " << n;
      EXPECT_EQ(split.nodes[n].serves.size(), one.nodes[n].serves.size()) << "node " << n;
      EXPECT_EQ(split.nodes[n].tiles.size(), one.nodes[n].tiles.size()) << "node " << n;
    }
    std::size_t crossing = 0;
    for (const auto& p : split.packets) {
      for (std::size_t h = 0; h < p.hops(); ++h)
        if (plan.rank_of(p.route[h]) != plan.rank_of(p.route[h + 1])) {
          ++crossing;
          break;
        }
      for (std::size_t i = 1; i < p.times.size(); ++i) EXPECT_LE(p.times[i - 1], p.times[i]) << "packet " << p.id;
    }
    EXPECT_GT(crossing, 0u);
    EXPECT_EQ(split.window, split.end);
  }
}

TEST(SplitMachine, RefusesMoreRanksThanNodesAndVirtualTimeOnEveryRank) {
  auto db = make_db("teapot:2", 1024, 8);
  MachineOptions options = options_for({"hypercube:1", 3}, db);
  auto run = run_split(make_db("teapot:2", 1024, 8), options, 3);
  for (const auto& e : run.errors) {
    ASSERT_TRUE(e);
    EXPECT_NE(what(e).find("3 ranks for a machine of 2 nodes"), std::string::npos) << what(e);
  }
  options = options_for({"hypercube:2", 2}, db);
  options.timing = nodes::CostModel{};
  run = run_split(std::move(db), options, 2);
  for (const auto& e : run.errors) {
    ASSERT_TRUE(e);
    EXPECT_NE(what(e).find("virtual time"), std::string::npos) << what(e);
  }
}

TEST(SplitMachine, BadSetUpOnRankZeroEndsEveryRankWithItsLine) {
  auto db = make_db("teapot:2", 1024, 8);
  MachineOptions options = options_for({"hypercube:2", 3}, db);
  options.cache.pages.reset();
  options.cache.kb = 0;  // less than a page: refused on rank 0, which alone knows the page size
  const auto run = run_split(std::move(db), options, 3);
  for (std::size_t r = 0; r < run.errors.size(); ++r) {
    ASSERT_TRUE(run.errors[r]) << "rank " << r;
    EXPECT_NE(what(run.errors[r]).find("less than one page"), std::string::npos) << what(run.errors[r]);
  }
  for (std::size_t r = 1; r < run.errors.size(); ++r)
    EXPECT_NE(what(run.errors[r]).find("rank 0: "), std::string::npos) << what(run.errors[r]);
}

TEST(SplitMachine, AProcessFailingOnRankZeroEndsEveryRank) {
  auto db = make_db("teapot:2", 1024, 16);
  MachineOptions options = options_for({"hypercube:4", 4}, db);
  options.progress = [](std::uint64_t done, std::uint64_t) {
    if (done > 40) throw std::runtime_error("injected failure");
  };
  const auto run = run_split(std::move(db), options, 4);
  for (std::size_t r = 0; r < run.errors.size(); ++r) {
    ASSERT_TRUE(run.errors[r]) << "rank " << r;
    EXPECT_EQ(what(run.errors[r]), "rank 0: process 'collector' failed: injected failure") << "rank " << r;
  }
}

// A transport whose rank fails after a number of polls: the bridge of that
// rank fails mid-run, as a rank whose wire breaks would.
class FailingTransport final : public nodes::Transport {
 public:
  FailingTransport(nodes::Transport& inner, int fail_after) : inner_(inner), left_(fail_after) {}
  int rank() const override { return inner_.rank(); }
  int size() const override { return inner_.size(); }
  void post(int to, nodes::Tag tag, nodes::Bytes message) override { inner_.post(to, tag, std::move(message)); }
  std::optional<nodes::Incoming> poll(nodes::Tag tag) override {
    if (tag == nodes::Tag::bridge && armed_ && --left_ == 0) {
      armed_ = false;
      throw std::runtime_error("injected wire failure");
    }
    return inner_.poll(tag);
  }
  void progress() override { inner_.progress(); }
  std::size_t pending() const override { return inner_.pending(); }

 private:
  nodes::Transport& inner_;
  int left_;
  bool armed_ = true;
};

TEST(SplitMachine, AFailureOnAnotherRankEndsEveryRankNamingThatRank) {
  auto db = make_db("teapot:2", 1024, 24);
  const MachineOptions options = options_for({"hypercube:4", 4}, db);
  std::optional<FailingTransport> failing;
  const auto run = run_split(std::move(db), options, 4, [&](nodes::Transport& t) -> nodes::Transport& {
    if (t.rank() != 2) return t;
    failing.emplace(t, 50);
    return *failing;
  });
  for (std::size_t r = 0; r < run.errors.size(); ++r) {
    ASSERT_TRUE(run.errors[r]) << "rank " << r;
    EXPECT_EQ(what(run.errors[r]), "rank 2: process 'bridge' failed: injected wire failure") << "rank " << r;
  }
}

TEST(RankPlan, BlocksFollowTheTopology) {
  // A 6-cube on 4 ranks: four 4-subcubes, cut by the two high dimensions.
  const nodes::RankPlan cube(topology::Topology::hypercube(6), 4);
  for (int r = 0; r < 4; ++r) {
    EXPECT_EQ(cube.first(r), static_cast<topology::NodeId>(16 * r));
    EXPECT_EQ(cube.count(r), 16u);
  }
  EXPECT_EQ(cube.cut_links(), 2u * 64 / 2);  // each node has two links across
  // A 4x4 mesh on 2 ranks: two strips of two rows, cut by 4 vertical links.
  EXPECT_EQ(nodes::RankPlan(topology::Topology::mesh(4, 4), 2).cut_links(), 4u);
  // Uneven: 16 nodes on 3 ranks, sizes 5, 5, 6, every node placed once.
  const nodes::RankPlan uneven(topology::Topology::ring(16), 3);
  std::vector<int> seen(16, 0);
  for (int r = 0; r < 3; ++r)
    for (auto n = uneven.first(r); n < uneven.first(r) + uneven.count(r); ++n) {
      ++seen[n];
      EXPECT_EQ(uneven.rank_of(n), r);
    }
  EXPECT_EQ(seen, std::vector<int>(16, 1));
  EXPECT_EQ(uneven.cut_links(), 3u);  // a ring cut into three arcs
  EXPECT_THROW(nodes::RankPlan(topology::Topology::ring(4), 5), std::invalid_argument);
  EXPECT_THROW(nodes::RankPlan(topology::Topology::ring(4), 0), std::invalid_argument);
}

}  // namespace
