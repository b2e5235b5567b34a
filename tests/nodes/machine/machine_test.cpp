// End-to-end invariants of the VM_pRAY machine: the image is bit-identical
// to the single-process render for every topology, size, cache, page size,
// grain, schedule, pixel order, worker count and thread count; every pixel is computed
// once; memory per processor stays within its share plus its cache; misses
// fall as the cache grows and equal the pages served; bad options fail with
// one line. Small frames keep the suite quick.
#include "nodes/machine/machine.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <utility>

#include "tests/nodes/machine/test_database.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"

namespace {

using nodes::MachineOptions;
using nodes::PixelOrder;
using nodes::Schedule;

using test::make_db;

std::vector<tracer::Color> reference(const std::string& spec, int size, bool spd) {
  const auto db = make_db(spec, 65536, size);
  tracer::InMemoryPageSource pages(db);
  tracer::RayStats stats;
  tracer::TraceOptions trace;
  trace.spd_procedure = spd;
  return tracer::render_frame(db.header, pages, trace, stats);
}

// Reference renders are shared between tests: they do not depend on options.
const std::vector<tracer::Color>& cached_reference(const std::string& spec, int size, bool spd = false) {
  static std::map<std::tuple<std::string, int, bool>, std::vector<tracer::Color>> cache;
  auto [it, fresh] = cache.try_emplace({spec, size, spd});
  if (fresh) it->second = reference(spec, size, spd);
  return it->second;
}

bool same_bits(const std::vector<tracer::Color>& a, const std::vector<tracer::Color>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(tracer::Color)) == 0;
}

struct Case {
  std::string topology;
  std::size_t nodes;
  std::uint32_t cache_pages;  // 0: the whole database
  std::uint32_t page_size;
  std::uint32_t grain;
  Schedule schedule;
  int workers;
  unsigned threads;
  std::string scene = "teapot:2";
  int size = 24;
  std::uint16_t prefetch = 1;
  PixelOrder order = PixelOrder::scanline;
  bool spd = false;  // SPD procedure: items are the (size + 1)^2 pixel corners
  bool record_tiles = false;
  bool forward_in_place = true;
  bool send_in_place = true;
  bool poll_rings = true;
};

nodes::MachineResult run_case(const Case& c) {
  MachineOptions options;
  options.topology = topology::parse_topology(c.topology, c.nodes);
  options.threads.count = c.threads;
  auto db = make_db(c.scene, c.page_size, c.size);
  options.cache.pages = c.cache_pages ? c.cache_pages : db.header.page_count;
  options.farming.grain = c.grain;
  options.farming.schedule = c.schedule;
  options.shape.workers_per_node = c.workers;
  options.farming.prefetch = c.prefetch;
  options.farming.pixel_order = c.order;
  options.trace.spd_procedure = c.spd;
  options.observe.record_tiles = c.record_tiles;
  options.threads.forward_in_place = c.forward_in_place;
  options.threads.send_in_place = c.send_in_place;
  options.threads.poll_rings = c.poll_rings;
  return nodes::run_machine(std::move(db), options);
}

std::string describe(const Case& c) {
  return c.topology + " n=" + std::to_string(c.nodes) + " cache=" + std::to_string(c.cache_pages) +
         " page=" + std::to_string(c.page_size) + " grain=" + std::to_string(c.grain) +
         " " + nodes::schedule_name(c.schedule) + " k=" + std::to_string(c.workers) +
         " threads=" + std::to_string(c.threads) + " prefetch=" + std::to_string(c.prefetch) + " " + c.scene + " " +
         nodes::pixel_order_name(c.order) + (c.spd ? " spd" : "");
}

TEST(Machine, ImageIsBitIdenticalToSingleProcessRenderAcrossConfigurations) {
  const std::vector<Case> cases{
      {"hypercube", 1, 1, 1024, 4, Schedule::dynamic, 1, 1},
      {"hypercube", 2, 1, 256, 1, Schedule::dynamic, 1, 1},
      {"ring", 3, 2, 1024, 4, Schedule::dynamic, 2, 1},
      {"complete", 3, 0, 65536, 7, Schedule::static_split, 1, 1},
      {"mesh", 3, 8, 1024, 4, Schedule::dynamic, 3, 1},
      {"torus", 4, 1, 256, 4, Schedule::dynamic, 3, 1},
      {"hypercube", 8, 16, 1024, 1, Schedule::static_split, 2, 1},
      {"mesh", 16, 4, 256, 4, Schedule::dynamic, 1, 1},
      {"torus", 16, 0, 1024, 64, Schedule::dynamic, 2, 1},
      {"hypercube", 16, 2, 1024, 576, Schedule::dynamic, 1, 1},
      {"ring", 16, 3, 1024, 4, Schedule::static_split, 1, 1},
      {"complete", 8, 1, 1024, 4, Schedule::dynamic, 3, 1},
      {"hypercube", 64, 4, 256, 2, Schedule::dynamic, 1, 1},
      {"torus", 64, 1, 1024, 4, Schedule::static_split, 2, 1},
      {"hypercube", 16, 2, 1024, 4, Schedule::dynamic, 2, 1, "balls:1", 24},
      {"hypercube", 16, 2, 256, 1, Schedule::affinity, 1, 1},
      {"ring", 5, 1, 1024, 3, Schedule::affinity, 2, 1},
      {"torus", 64, 3, 1024, 2, Schedule::affinity, 1, 1},
      {"hypercube", 16, 2, 256, 4, Schedule::dynamic, 1, 1, "teapot:2", 24, 1, PixelOrder::hilbert},
      {"ring", 5, 1, 1024, 7, Schedule::static_split, 2, 1, "teapot:2", 24, 0, PixelOrder::hilbert},
      {"mesh", 6, 3, 1024, 3, Schedule::affinity, 1, 1, "teapot:2", 24, 2, PixelOrder::hilbert},
      {"complete", 3, 1, 1024, 5, Schedule::dynamic, 2, 1, "teapot:2", 23, 1, PixelOrder::hilbert},
  };
  for (const auto& c : cases) {
    const auto result = run_case(c);
    EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size))) << describe(c);
  }
}

// Processors spread over two OS threads: links between them cross threads.
TEST(Machine, ImageIsBitIdenticalOnTwoThreads) {
  const std::vector<Case> cases{
      {"hypercube", 2, 1, 256, 1, Schedule::dynamic, 1, 2},
      {"torus", 4, 1, 256, 4, Schedule::dynamic, 3, 2},
      {"mesh", 4, 3, 1024, 4, Schedule::dynamic, 2, 2},
      {"hypercube", 8, 2, 256, 2, Schedule::affinity, 2, 2},
      // Tiles longer than a pixel computer's timeslice: workers yield
      // mid-tile and share a one-page cache.
      {"ring", 4, 1, 256, 48, Schedule::dynamic, 3, 2},
      {"torus", 9, 2, 1024, 5, Schedule::affinity, 2, 2, "teapot:2", 24, 1, PixelOrder::hilbert},
  };
  for (const auto& c : cases) {
    const auto result = run_case(c);
    EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size))) << describe(c);
  }
}

// Every packet on a link between two threads goes through the relays once:
// what the relays put in rings, they take out, and it is what the routers
// sent on those links. Without relays the machine computes the same.
TEST(Machine, RelaysCarryEveryPacketBetweenThreadsOnce) {
  const Case c{"hypercube", 16, 2, 256, 4, Schedule::dynamic, 1, 2};
  const auto relayed = run_case(c);
  const auto& r = relayed.report;
  ASSERT_EQ(r.relays.size(), 2u);
  std::uint64_t expected = 0, crossing = 0;
  for (const auto& l : r.network.links)
    if (nodes::Network::block_placement(l.from, 16, 2) != nodes::Network::block_placement(l.to, 16, 2)) {
      expected += l.packets;
      ++crossing;
    }
  EXPECT_GT(expected, 0u);
  EXPECT_EQ(crossing, 16u);  // a 4-cube halved: the links of one dimension, both ways
  EXPECT_EQ(r.relayed_links % crossing, 0u);  // per direction, one per buffer class
  std::uint64_t sent = 0, received = 0;
  for (const auto& t : r.relays) {
    sent += t.packets_sent;
    received += t.packets_received;
    EXPECT_GT(t.wakes, 0u);
    EXPECT_LE(t.signals, t.packets_sent + t.packets_received);  // batches, never more than one per packet
  }
  EXPECT_EQ(sent, expected);
  EXPECT_EQ(received, expected);

  MachineOptions options;
  options.topology = topology::parse_topology(c.topology, c.nodes);
  options.threads.count = 2;
  options.threads.relay_between = false;
  auto db = make_db(c.scene, c.page_size, c.size);
  options.cache.pages = c.cache_pages;
  options.farming.grain = c.grain;
  const auto plain = nodes::run_machine(std::move(db), options);
  EXPECT_TRUE(plain.report.relays.empty());
  EXPECT_EQ(plain.report.relayed_links, 0u);
  EXPECT_TRUE(same_bits(plain.image.pixels(), relayed.image.pixels()));
  EXPECT_TRUE(same_bits(relayed.image.pixels(), cached_reference(c.scene, c.size)));
}

// Two runs of one case under a static schedule (each node's pixels fixed,
// so its misses too) that differ only in how packets cross threads: the
// same image as the plain renderer's, the same packets and bytes on every
// link, hops, misses and pages served. Returns the relays' counts of each.
std::pair<nodes::RelayCounters, nodes::RelayCounters> expect_same_traffic(const Case& c,
                                                                          const nodes::MachineResult& x,
                                                                          const nodes::MachineResult& y) {
  EXPECT_TRUE(same_bits(x.image.pixels(), y.image.pixels()));
  EXPECT_TRUE(same_bits(y.image.pixels(), cached_reference(c.scene, c.size)));
  const auto& a = x.report.network;
  const auto& b = y.report.network;
  EXPECT_EQ(a.links.size(), b.links.size());
  for (std::size_t l = 0; l < std::min(a.links.size(), b.links.size()); ++l) {
    EXPECT_EQ(a.links[l].packets, b.links[l].packets) << l;
    EXPECT_EQ(a.links[l].bytes, b.links[l].bytes) << l;
  }
  EXPECT_EQ(a.hops.total_hops, b.hops.total_hops);
  EXPECT_EQ(x.report.svm().misses, y.report.svm().misses);
  EXPECT_EQ(x.report.served().pages_served, y.report.served().pages_served);
  std::pair<nodes::RelayCounters, nodes::RelayCounters> counts;
  for (const auto& r : x.report.relays) counts.first += r;
  for (const auto& r : y.report.relays) counts.second += r;
  EXPECT_EQ(counts.first.packets_sent, counts.second.packets_sent);
  return counts;
}

// Routers that put packets for another thread into the relays' rings
// themselves (the default), or leave every one to their thread's relay:
// the same traffic; only the relays' counts say who moved the packets.
TEST(Machine, RoutersSendingAcrossThreadsInPlaceChangeNothingButWhoMovesPackets) {
  for (const unsigned threads : {2u, 3u})
    for (const char* topology : {"hypercube", "torus"}) {
      Case c{topology, 16, 2, 256, 4, Schedule::static_split, 1, threads};
      SCOPED_TRACE(describe(c));
      c.send_in_place = false;
      const auto relays = run_case(c);
      c.send_in_place = true;
      const auto routers = run_case(c);
      const auto [alone, both] = expect_same_traffic(c, relays, routers);
      EXPECT_EQ(alone.sent_in_place, 0u);
      EXPECT_GT(both.sent_in_place, 0u);
      EXPECT_LE(both.sent_in_place, both.packets_sent);
    }
}

// Threads that poll the relays' rings (the default), or relays that signal
// each batch: the same traffic, every packet between threads carried.
TEST(Machine, PollingOrSignallingTheRingsChangesNothingButHowThreadsLearn) {
  for (const unsigned threads : {2u, 3u})
    for (const char* topology : {"hypercube", "complete"}) {
      Case c{topology, 16, 2, 256, 4, Schedule::static_split, 1, threads};
      SCOPED_TRACE(describe(c));
      c.poll_rings = false;
      const auto signalled = run_case(c);
      c.poll_rings = true;
      const auto polled = run_case(c);
      const auto [s, p] = expect_same_traffic(c, signalled, polled);
      EXPECT_EQ(p.packets_sent, p.packets_received);
      EXPECT_EQ(s.packets_sent, s.packets_received);
      EXPECT_GT(p.packets_sent, 0u);
    }
}

// Router steps and page serves taken in place by the senders on the
// router's thread (the default) or only by the routers and page servers:
// the same image, and each packet's hops within the topology's diameter; in
// place only where a sender shares the thread.
TEST(Machine, RoutingInPlaceComputesWhatTheRoutersAloneCompute) {
  for (const unsigned threads : {1u, 2u})
    for (const char* topology : {"hypercube", "ring", "torus"}) {
      Case c{topology, 16, 2, 256, 4, Schedule::dynamic, 2, threads};
      SCOPED_TRACE(describe(c));
      c.forward_in_place = false;
      const auto alone = run_case(c);
      c.forward_in_place = true;
      const auto in_place = run_case(c);
      EXPECT_TRUE(same_bits(alone.image.pixels(), in_place.image.pixels()));
      EXPECT_TRUE(same_bits(in_place.image.pixels(), cached_reference(c.scene, c.size)));
      std::uint64_t taken = 0, taken_alone = 0;
      for (const auto& r : in_place.report.network.routers) taken += r.in_place;
      for (const auto& r : alone.report.network.routers) taken_alone += r.in_place;
      EXPECT_EQ(taken_alone, 0u);
      EXPECT_GT(taken, 0u);
      // Page requests served by their deliverer, and every one answered once.
      EXPECT_EQ(alone.report.served().served_in_place, 0u);
      EXPECT_GT(in_place.report.served().served_in_place, 0u);
      EXPECT_LE(in_place.report.served().served_in_place, in_place.report.served().pages_served);
      EXPECT_EQ(in_place.report.served().pages_served, in_place.report.svm().misses);
      const auto& t = in_place.report.topology;
      EXPECT_LE(in_place.report.network.hops.max_hops, t.diameter());
      EXPECT_GT(in_place.report.network.hops.packets, 0u);
    }
}

TEST(Machine, ImageIsBitIdenticalOn256Nodes) {
  const Case c{"hypercube", 256, 2, 256, 1, Schedule::dynamic, 1, 1, "teapot:2", 16};
  EXPECT_TRUE(same_bits(run_case(c).image.pixels(), cached_reference(c.scene, c.size)));
}

TEST(Machine, SpdProcedureMatchesSingleProcessSpdRender) {
  const std::vector<Case> cases{
      {"mesh", 4, 3, 1024, 16, Schedule::dynamic, 2, 1, "teapot:2", 20, 1, PixelOrder::scanline, true},
      {"ring", 3, 2, 1024, 5, Schedule::affinity, 1, 1, "teapot:2", 19, 1, PixelOrder::hilbert, true},
  };
  for (const Case& c : cases) {
    const auto result = run_case(c);
    EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size, true))) << describe(c);
    const auto corners = static_cast<std::uint64_t>(c.size + 1) * static_cast<std::uint64_t>(c.size + 1);
    EXPECT_EQ(result.report.items, corners) << describe(c);
    EXPECT_EQ(result.report.pixel_order, c.order) << describe(c);
  }
}

// Static shares of a Hilbert order on a 2^k square frame are its quadrants,
// and the owners map is in scanline order like the image.
TEST(Machine, HilbertStaticSharesAreQuadrantsOfTheOwnersMap) {
  const Case c{"hypercube", 4, 0, 1024, 1, Schedule::static_split, 1, 1, "teapot:2", 32, 1, PixelOrder::hilbert};
  const auto result = run_case(c);
  EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size)));
  const auto& owners = result.report.owners;
  ASSERT_EQ(owners.size(), 32u * 32u);
  // The curve runs from (0, 0) to (31, 0): first quadrant, the two far ones, last quadrant.
  const auto quadrant_node = [](int x, int y) { return x < 16 ? (y < 16 ? 0 : 1) : (y < 16 ? 3 : 2); };
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      ASSERT_EQ(owners[static_cast<std::size_t>(y * 32 + x)], quadrant_node(x, y)) << x << "," << y;
}

// Compact patches share pages: with one worker per node and a static share,
// each node's accesses do not depend on scheduling, so the counts are exact.
TEST(Machine, HilbertOrderCutsTheMissesOfStaticShares) {
  Case c{"hypercube", 16, 24, 1024, 16, Schedule::static_split, 1, 1, "teapot:3", 64};
  const std::uint64_t scanline = run_case(c).report.svm().misses;
  c.order = PixelOrder::hilbert;
  const std::uint64_t hilbert = run_case(c).report.svm().misses;
  EXPECT_LT(hilbert, scanline * 3 / 4) << "scanline " << scanline << ", hilbert " << hilbert;
}

TEST(Machine, EveryPixelIsComputedExactlyOnce) {
  const Case c{"torus", 16, 4, 1024, 3, Schedule::dynamic, 2, 1};
  const auto result = run_case(c);
  const auto& r = result.report;
  const std::uint64_t pixels = 24 * 24;
  EXPECT_EQ(r.items, pixels);
  EXPECT_EQ(r.farmer.items, pixels);
  EXPECT_EQ(r.collected, pixels);
  EXPECT_EQ(r.items_computed(), pixels);
  // Each worker is owed prefetch + 1 answers at the end, all of them stops.
  EXPECT_EQ(r.farmer.stops, 16u * 2u * 2u);
  EXPECT_EQ(r.farmer.results, r.farmer.tiles);
  EXPECT_EQ(r.rays().samples, pixels);
}

// Progress starts at 0 once the machine runs, never falls, and ends at the
// frame's items, on the collector's one thread.
TEST(Machine, ProgressStartsAtZeroAndEndsAtTheFrame) {
  MachineOptions options;
  options.topology = topology::parse_topology("ring", 4);
  options.threads.count = 2;
  auto db = make_db("teapot:2", 1024, 16);
  options.cache.pages = db.header.page_count;
  std::vector<std::uint64_t> seen;
  std::set<std::thread::id> threads;
  options.progress = [&](std::uint64_t done, std::uint64_t total) {
    EXPECT_EQ(total, 256u);
    seen.push_back(done);
    threads.insert(std::this_thread::get_id());
  };
  nodes::run_machine(std::move(db), options);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_EQ(seen.front(), 0u);
  EXPECT_EQ(seen.back(), 256u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(threads.size(), 1u);
}

// The tile timeline accounts for the whole run: each item in exactly one
// tile, and per node the tiles' items, page requests and rays add up to the
// node's counts; no tile ends before it starts. Off by default.
TEST(Machine, RecordedTilesCoverEveryItemOnceAndAddUpPerNode) {
  Case c{"hypercube", 8, 2, 256, 3, Schedule::affinity, 2, 2};
  EXPECT_TRUE(run_case(c).report.per_node[0].work.spans.empty());
  c.record_tiles = true;
  const auto result = run_case(c);
  const auto& r = result.report;
  EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size)));
  std::vector<int> times_computed(r.items, 0);
  for (const nodes::NodeReport& node : r.per_node) {
    std::uint64_t items = 0, requests = 0, rays = 0;
    for (const nodes::TileSpan& s : node.work.spans) {
      EXPECT_GE(s.worker, 0);
      EXPECT_LT(s.worker, c.workers);
      EXPECT_LE(s.start, s.end);
      EXPECT_GE(s.start, 0.0);
      EXPECT_LE(s.end, r.wall_seconds);
      for (std::uint32_t i = s.tile.first; i < s.tile.first + s.tile.count; ++i) ++times_computed.at(i);
      items += s.tile.count;
      requests += s.page_requests;
      rays += s.rays;
    }
    EXPECT_EQ(node.work.spans.size(), node.work.tiles);
    EXPECT_EQ(items, node.work.items);
    EXPECT_EQ(requests, node.svm.misses);
    EXPECT_EQ(rays, node.work.rays.rays());
  }
  EXPECT_EQ(std::count(times_computed.begin(), times_computed.end(), 1), static_cast<long>(r.items));
}

// Prefetch changes only when work arrives: the same image, every item once,
// and one request per worker plus one result per tile on the network.
TEST(Machine, PrefetchKeepsTheImageAndTheCounts) {
  for (std::uint16_t prefetch = 0; prefetch <= 3; ++prefetch) {
    for (Case c : {Case{"hypercube", 8, 2, 256, 3, Schedule::dynamic, 2, 1},
                   Case{"ring", 5, 1, 1024, 7, Schedule::static_split, 1, 1},
                   Case{"torus", 4, 1, 256, 4, Schedule::dynamic, 3, 2},
                   Case{"mesh", 6, 2, 1024, 2, Schedule::affinity, 2, 1}}) {
      c.prefetch = prefetch;
      const auto result = run_case(c);
      const auto& r = result.report;
      EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference(c.scene, c.size))) << describe(c);
      EXPECT_EQ(r.items_computed(), r.items) << describe(c);
      EXPECT_EQ(r.farmer.results, r.farmer.tiles) << describe(c);
      const std::uint64_t workers = c.nodes * static_cast<std::uint64_t>(c.workers);
      EXPECT_EQ(r.farmer.stops, workers * (prefetch + 1u)) << describe(c);
      const auto& kinds = r.network.hops_by_kind;
      EXPECT_EQ(kinds.at(static_cast<std::uint8_t>(nodes::MessageKind::work_request)).packets, workers)
          << describe(c);
      EXPECT_EQ(kinds.at(static_cast<std::uint8_t>(nodes::MessageKind::result)).packets, r.farmer.tiles)
          << describe(c);
    }
  }
}

TEST(Machine, ResidentSceneBytesStayWithinOwnShareAndCache) {
  for (const auto& c : {Case{"hypercube", 16, 3, 256, 4, Schedule::dynamic, 3, 1},
                        Case{"ring", 8, 1, 1024, 1, Schedule::dynamic, 1, 1}}) {
    const auto result = run_case(c);
    for (const auto& node : result.report.per_node) {
      EXPECT_LE(node.peak_resident_bytes, node.own_bytes + std::size_t{c.cache_pages} * c.page_size)
          << describe(c);
      EXPECT_LE(node.cache_capacity, c.cache_pages);
    }
  }
}

TEST(Machine, LargeSceneOn64NodesKeepsASmallFractionPerProcessor) {
  MachineOptions options;
  options.topology = topology::parse_topology("hypercube", 64);
  options.threads.count = 1;
  options.cache.pages = 64;
  auto db = make_db("tetra:7", 1024, 16);
  const std::uint64_t database_bytes = db.header.bytes();
  ASSERT_GT(db.header.page_count, 64u * 8u);
  const auto result = nodes::run_machine(std::move(db), options);
  for (const auto& node : result.report.per_node) {
    EXPECT_LE(node.peak_resident_bytes, node.own_bytes + 64u * 1024u);
    EXPECT_LT(static_cast<double>(node.peak_resident_bytes), 0.1 * static_cast<double>(database_bytes));
  }
  EXPECT_TRUE(same_bits(result.image.pixels(), cached_reference("tetra:7", 16)));
}

TEST(Machine, MissRatioFallsAsTheCacheGrowsAndVanishesWhenItHoldsEverything) {
  // A static split gives every node the same access sequence in every run,
  // so LRU's inclusion property makes misses non-increasing in cache size.
  double previous = 1.0;
  for (std::uint32_t cache : {1u, 2u, 4u, 16u, 64u, 0u}) {
    const auto result = run_case({"hypercube", 4, cache, 256, 4, Schedule::static_split, 1, 1});
    const auto svm = result.report.svm();
    EXPECT_LE(svm.miss_ratio(), previous) << "cache " << cache;
    previous = svm.miss_ratio();
    EXPECT_EQ(result.report.served().pages_served, svm.misses);
    EXPECT_EQ(svm.accesses(), result.report.rays().page_calls);
    if (cache == 0) {
      // Only cold misses remain: no page is ever evicted, so each node
      // fetches each remote page it touches exactly once.
      for (const auto& node : result.report.per_node) {
        EXPECT_EQ(node.evictions, 0u);
        EXPECT_LE(node.svm.misses, result.report.page_count - node.own_bytes / 256);
      }
    }
  }
}

TEST(Machine, DefaultCacheIsAnEighthOfTheDatabaseButNeverTooSmallForARay) {
  tracer::DatabaseHeader header;
  header.page_count = 3;
  EXPECT_EQ(nodes::default_cache_pages(header), 3u);
  header.page_count = 200;
  EXPECT_EQ(nodes::default_cache_pages(header), 64u);
  header.page_count = 661;
  EXPECT_EQ(nodes::default_cache_pages(header), 82u);

  // A database of a few pages on 16 nodes: an eighth of it would be less
  // than the pages one ray visits, and nearly every access would miss. The
  // default holds it all, so each node fetches each remote page once.
  tracer::Database db = make_db("balls:1", 1024, 32);
  const std::uint32_t pages = db.header.page_count;
  ASSERT_LT(pages, 16u);
  MachineOptions options;
  options.topology = topology::parse_topology("hypercube", 16);
  options.threads.count = 1;
  const auto result = nodes::run_machine(std::move(db), options);
  for (const auto& node : result.report.per_node) {
    EXPECT_EQ(node.cache_capacity + node.own_bytes / 1024, pages);  // every page it does not own
    EXPECT_EQ(node.evictions, 0u);
    EXPECT_LE(node.svm.misses, pages);
  }
}

// --threads 0 takes the CPUs, but leaves each thread two pixel computers,
// so that one waiting for a page does not idle its thread, save that two
// nodes get two threads when two CPUs are there; a number given is taken as
// it is, at most one thread a node.
TEST(Machine, DefaultThreadsLeaveEachThreadTwoPixelComputers) {
  MachineOptions o;
  o.threads.cpus = 16;
  EXPECT_EQ(nodes::thread_count(o, 16), 8u);
  EXPECT_EQ(nodes::thread_count(o, 64), 16u);
  EXPECT_EQ(nodes::thread_count(o, 256), 16u);
  EXPECT_EQ(nodes::thread_count(o, 5), 2u);
  EXPECT_EQ(nodes::thread_count(o, 3), 2u);
  EXPECT_EQ(nodes::thread_count(o, 2), 2u);
  EXPECT_EQ(nodes::thread_count(o, 1), 1u);
  o.shape.workers_per_node = 4;
  EXPECT_EQ(nodes::thread_count(o, 16), 16u);
  EXPECT_EQ(nodes::thread_count(o, 2), 2u);
  o.threads.cpus = 2;
  o.shape.workers_per_node = 1;
  EXPECT_EQ(nodes::thread_count(o, 16), 2u);
  EXPECT_EQ(nodes::thread_count(o, 3), 2u);
  o.threads.cpus = 1;
  EXPECT_EQ(nodes::thread_count(o, 2), 1u);
  o.threads.cpus = 2;
  o.threads.count = 16;
  o.threads.cpus = 0;
  EXPECT_EQ(nodes::thread_count(o, 16), 16u);
  EXPECT_EQ(nodes::thread_count(o, 4), 4u);

  // And a run takes what the rule says.
  MachineOptions run;
  run.topology = topology::parse_topology("hypercube", 4);
  run.threads.cpus = 4;
  EXPECT_EQ(nodes::run_machine(make_db("balls:1", 1024, 16), run).report.threads, 2u);
}

// Pixel computers answer a packet for their thread at once when it holds at
// most four of them, counted with their workers; never on one thread of a
// whole machine or under a schedule seed (not prioritised, or seeded).
TEST(Machine, PixelComputersAnswerAtOnceWhenTheirThreadHoldsFew) {
  MachineOptions o;
  EXPECT_TRUE(nodes::answers_at_once(o, 2, 2, true));
  EXPECT_TRUE(nodes::answers_at_once(o, 8, 2, true));
  EXPECT_FALSE(nodes::answers_at_once(o, 16, 2, true));
  EXPECT_TRUE(nodes::answers_at_once(o, 64, 16, true));
  EXPECT_FALSE(nodes::answers_at_once(o, 256, 16, true));
  EXPECT_FALSE(nodes::answers_at_once(o, 2, 2, false));
  o.shape.workers_per_node = 4;
  EXPECT_TRUE(nodes::answers_at_once(o, 2, 2, true));
  EXPECT_FALSE(nodes::answers_at_once(o, 4, 2, true));
  o.shape.workers_per_node = 1;
  o.threads.answer_at_once = true;  // set to measure the rule: taken where pixel computers yield at all
  EXPECT_TRUE(nodes::answers_at_once(o, 256, 16, true));
  EXPECT_FALSE(nodes::answers_at_once(o, 256, 16, false));
  o.threads.answer_at_once = false;
  EXPECT_FALSE(nodes::answers_at_once(o, 2, 2, true));
  o.threads.answer_at_once.reset();
  o.schedule_seed = 7;
  EXPECT_FALSE(nodes::answers_at_once(o, 2, 2, true));
}

// And before every ray too, where each thread holds one pixel computer.
TEST(Machine, APixelComputerAloneOnItsThreadAnswersBetweenRays) {
  MachineOptions o;
  EXPECT_TRUE(nodes::answers_between_rays(o, 2, 2, true));
  EXPECT_TRUE(nodes::answers_between_rays(o, 16, 16, true));
  EXPECT_FALSE(nodes::answers_between_rays(o, 4, 2, true));  // two a thread: after every pixel only
  EXPECT_TRUE(nodes::answers_at_once(o, 4, 2, true));
  EXPECT_FALSE(nodes::answers_between_rays(o, 2, 2, false));
  o.shape.workers_per_node = 2;  // two on each node's thread
  EXPECT_FALSE(nodes::answers_between_rays(o, 2, 2, true));
  o.shape.workers_per_node = 1;
  o.threads.answer_at_once = false;
  EXPECT_FALSE(nodes::answers_between_rays(o, 2, 2, true));
}

// Answering at once changes when packets are handled, never what the run
// computes: two nodes on two threads give the image and the statistics of
// one thread.
TEST(Machine, AnsweringAtOnceGivesTheImageAndStatisticsOfOneThread) {
  const tracer::Database db = make_db("rings:1", 1024, 48);
  MachineOptions one;
  one.topology = topology::parse_topology("hypercube", 2);
  one.threads.count = 1;
  MachineOptions two = one;
  two.threads.count = 2;
  ASSERT_TRUE(nodes::answers_at_once(two, 2, 2, true));
  const nodes::MachineResult a = nodes::run_machine(db, one), b = nodes::run_machine(db, two);
  EXPECT_EQ(a.image.pixels(), b.image.pixels());
  EXPECT_EQ(a.report.svm().misses, b.report.svm().misses);
  EXPECT_EQ(a.report.rays().rays(), b.report.rays().rays());
  EXPECT_EQ(b.report.threads, 2u);
}

TEST(Machine, PageCommunicationsEqualMissesWithSharedCaches) {
  const auto result = run_case({"mesh", 9, 2, 256, 2, Schedule::dynamic, 3, 1});
  EXPECT_EQ(result.report.served().pages_served, result.report.svm().misses);
  EXPECT_EQ(result.report.served().bytes_served, result.report.svm().misses * 256u);
}

void expect_error(const Case& c, MachineOptions options, const std::string& fragment) {
  try {
    options.topology = topology::parse_topology(c.topology, c.nodes);
    nodes::run_machine(make_db(c.scene, c.page_size, 8), options);
    ADD_FAILURE() << "no error for " << fragment;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(Machine, BadOptionsFailWithOneLineNamingTheField) {
  const Case c{"hypercube", 4, 1, 1024, 4, Schedule::dynamic, 1, 1};
  MachineOptions zero_cache;
  zero_cache.cache.pages = 0;
  expect_error(c, zero_cache, "cache_pages");
  MachineOptions tiny_kb;
  tiny_kb.cache.kb = 0;
  expect_error(c, tiny_kb, "cache_kb");
  MachineOptions workers;
  workers.shape.workers_per_node = 0;
  expect_error(c, workers, "workers_per_node");
  workers.shape.workers_per_node = nodes::max_workers_per_node + 1;
  expect_error(c, workers, "workers_per_node: must be at most 64, got 65");
  MachineOptions grain;
  grain.farming.grain = 0;
  expect_error(c, grain, "grain");
  grain.farming.grain = nodes::max_grain + 1;
  expect_error(c, grain, "grain: must be at most 1048576");
  MachineOptions prefetch;
  prefetch.farming.prefetch = 4;  // the network buffers 4 packets per queue
  expect_error(c, prefetch, "prefetch");
  expect_error({"hypercube", 48, 1, 1024, 4, Schedule::dynamic, 1, 1}, MachineOptions{}, "48");
  expect_error({"mesh:8x8", 32, 1, 1024, 4, Schedule::dynamic, 1, 1}, MachineOptions{}, "32");
}

TEST(Machine, PageSizeErrorsComeFromTheDatabaseBuild) {
  EXPECT_THROW(make_db("teapot:2", 1000, 8), tracer::DatabaseError);
}

}  // namespace
