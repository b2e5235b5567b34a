// The header and the reports ranks send one another (report_wire.hpp):
// each comes back field for field with every field set to its own value,
// its bytes are its fields at their widths in their order (the layout
// written out here by hand, as the ranks of a run and stored reports rely
// on it) and as many as its field list promises, a message cut anywhere
// short is refused, and so is a count beyond the message. Structs that travel as
// their bytes are filled and compared bytewise; the sizes asserted here say
// they have no padding.
#include "nodes/machine/report_wire.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "nodes/machine/node_report.hpp"
#include "nodes/machine/recorder.hpp"
#include "wire_support.hpp"

namespace {

using nodes::Bytes;
using nodes::WireReader;
using nodes::WireWriter;
using wire_test::expect_prefixes_refused;
using wire_test::patterned;
using wire_test::same_bytes;

static_assert(std::has_unique_object_representations_v<nodes::SvmStats>);
static_assert(std::has_unique_object_representations_v<nodes::ServerCounters>);
static_assert(std::has_unique_object_representations_v<tracer::RayStats>);
static_assert(std::has_unique_object_representations_v<nodes::BridgeCounters>);
static_assert(std::has_unique_object_representations_v<nodes::LinkCounters>);
static_assert(sizeof(csp::ThreadUse) == 6 * 8 + 4 * 8);
static_assert(sizeof(tracer::Camera) == 3 * 24 + 2 * 8 + 2 * 4);
static_assert(sizeof(tracer::Color) == 12 && sizeof(tracer::LightRecord) == 24);
static_assert(sizeof(tracer::SectionLayout) == 12 && sizeof(tracer::Box3f) == 24);

tracer::DatabaseHeader header() {
  tracer::DatabaseHeader h;
  h.scene_name = "wire scene";
  h.camera = patterned<tracer::Camera>(1);
  h.background = patterned<tracer::Color>(101);
  h.lights = {patterned<tracer::LightRecord>(2), patterned<tracer::LightRecord>(30)};
  h.page_size = 8192;
  h.page_shift = 13;
  h.page_count = 321;
  for (std::size_t s = 0; s < std::size(h.sections); ++s)
    h.sections[s] = patterned<tracer::SectionLayout>(static_cast<unsigned>(60 + 13 * s));
  h.accel = tracer::Accel::grid;
  h.bounds = patterned<tracer::Box3f>(140);
  h.bvh_root = patterned<tracer::BvhNode>(3);
  h.bvh_depth = 19;
  h.grid_dims[0] = 5;
  h.grid_dims[1] = 6;
  h.grid_dims[2] = 7;
  h.epsilon = 0.0625f;
  h.polygon_count = 1001;
  h.object_count = 1002;
  h.primitive_count = 1003;
  return h;
}

nodes::NodeReport node_report() {
  nodes::NodeReport n;
  n.svm = patterned<nodes::SvmStats>(1);
  n.served = patterned<nodes::ServerCounters>(40);
  n.work.items = 11;
  n.work.tiles = 12;
  n.work.rays = patterned<tracer::RayStats>(60);
  n.work.spans = {{1, {2, 3}, 4.5, 5.5, 6, 7}, {8, {9, 10}, 11.5, 12.5, 13, 14}};
  n.own_bytes = 21;
  n.peak_resident_bytes = 22;
  n.cache_capacity = 23;
  n.evictions = 24;
  return n;
}

nodes::RouterCounters router_counters() {
  nodes::RouterCounters c;
  c.injected = 31;
  c.forwarded = 32;
  c.in_place = 21;
  c.delivered = 33;
  c.peak_pending = 34;
  c.sent = {patterned<nodes::LinkCounters>(1), patterned<nodes::LinkCounters>(20)};
  c.hops = {35, 36, 37};
  for (std::size_t k = 0; k < c.hops_by_kind.size(); ++k)
    c.hops_by_kind[k] = {k + 1, k + 2, static_cast<std::uint32_t>(k + 3)};
  c.routes = {{41, 42, {1, 2, 3}}, {43, 44, {}}, {45, 46, {7}}};
  return c;
}

nodes::RankReport rank_report() {
  nodes::RankReport k;
  k.rank = 3;
  k.first_node = 51;
  k.node_count = 52;
  k.threads = 53;
  k.bridge = patterned<nodes::BridgeCounters>(1);
  k.wall_seconds = 54.5;
  k.cpu_seconds = 55.25;
  k.peak_scene_bytes = 56;
  return k;
}

const std::vector<csp::ThreadUse> threads{patterned<csp::ThreadUse>(1), patterned<csp::ThreadUse>(100)};

void expect_same(const nodes::HopSummary& a, const nodes::HopSummary& b) {
  EXPECT_EQ(a.packets, b.packets);
  EXPECT_EQ(a.total_hops, b.total_hops);
  EXPECT_EQ(a.max_hops, b.max_hops);
}

template <class Put>
Bytes encoded(Put put) {
  WireWriter w;
  put(w);
  return w.take();
}

TEST(ReportWire, HeaderRoundTrips) {
  const tracer::DatabaseHeader h = header();
  const Bytes bytes = encoded([&](WireWriter& w) { nodes::put_header(w, h); });
  EXPECT_EQ(bytes.size(), 8 + h.scene_name.size() + sizeof(h.camera) + sizeof(h.background) + 8 +
                              2 * sizeof(tracer::LightRecord) + 3 * 4 + sizeof(h.sections) + sizeof(h.accel) +
                              sizeof(h.bounds) + sizeof(h.bvh_root) + 4 + 3 * 4 + 4 + 3 * 8);
  WireWriter layout;
  layout.put_string(h.scene_name);
  layout.put(h.camera);
  layout.put(h.background);
  layout.put_vector(h.lights);
  for (std::uint32_t x : {h.page_size, h.page_shift, h.page_count}) layout.put(x);
  layout.put(h.sections);
  layout.put(h.accel);
  layout.put(h.bounds);
  layout.put(h.bvh_root);
  layout.put(h.bvh_depth);
  layout.put(h.grid_dims);
  layout.put(h.epsilon);
  for (std::uint64_t x : {h.polygon_count, h.object_count, h.primitive_count}) layout.put(x);
  EXPECT_EQ(bytes, layout.take());
  WireReader r(bytes);
  const tracer::DatabaseHeader back = nodes::get_header(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.scene_name, h.scene_name);
  EXPECT_TRUE(same_bytes(back.camera, h.camera));
  EXPECT_TRUE(same_bytes(back.background, h.background));
  ASSERT_EQ(back.lights.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(same_bytes(back.lights[i], h.lights[i]));
  EXPECT_EQ(back.page_size, h.page_size);
  EXPECT_EQ(back.page_shift, h.page_shift);
  EXPECT_EQ(back.page_count, h.page_count);
  EXPECT_TRUE(same_bytes(back.sections, h.sections));
  EXPECT_EQ(back.accel, h.accel);
  EXPECT_TRUE(same_bytes(back.bounds, h.bounds));
  EXPECT_TRUE(same_bytes(back.bvh_root, h.bvh_root));
  EXPECT_EQ(back.bvh_depth, h.bvh_depth);
  EXPECT_TRUE(same_bytes(back.grid_dims, h.grid_dims));
  EXPECT_EQ(back.epsilon, h.epsilon);
  EXPECT_EQ(back.polygon_count, h.polygon_count);
  EXPECT_EQ(back.object_count, h.object_count);
  EXPECT_EQ(back.primitive_count, h.primitive_count);
}

TEST(ReportWire, NodeReportRoundTrips) {
  const nodes::NodeReport n = node_report();
  const Bytes bytes = encoded([&](WireWriter& w) { nodes::put_node_report(w, n); });
  EXPECT_EQ(bytes.size(), sizeof(n.svm) + sizeof(n.served) + 8 + 8 + sizeof(n.work.rays) + 8 +
                              2 * sizeof(nodes::TileSpan) + 8 + 8 + 4 + 8);
  WireWriter layout;
  layout.put(n.svm);
  layout.put(n.served);
  layout.put(n.work.items);
  layout.put(n.work.tiles);
  layout.put(n.work.rays);
  layout.put_vector(n.work.spans);
  layout.put(n.own_bytes);
  layout.put(n.peak_resident_bytes);
  layout.put(n.cache_capacity);
  layout.put(n.evictions);
  EXPECT_EQ(bytes, layout.take());
  WireReader r(bytes);
  const nodes::NodeReport back = nodes::get_node_report(r);
  EXPECT_TRUE(r.done());
  EXPECT_TRUE(same_bytes(back.svm, n.svm));
  EXPECT_TRUE(same_bytes(back.served, n.served));
  EXPECT_EQ(back.work.items, n.work.items);
  EXPECT_EQ(back.work.tiles, n.work.tiles);
  EXPECT_TRUE(same_bytes(back.work.rays, n.work.rays));
  ASSERT_EQ(back.work.spans.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const nodes::TileSpan &got = back.work.spans[i], &sent = n.work.spans[i];
    EXPECT_EQ(got.worker, sent.worker);
    EXPECT_EQ(got.tile, sent.tile);
    EXPECT_EQ(got.start, sent.start);
    EXPECT_EQ(got.end, sent.end);
    EXPECT_EQ(got.page_requests, sent.page_requests);
    EXPECT_EQ(got.rays, sent.rays);
  }
  EXPECT_EQ(back.own_bytes, n.own_bytes);
  EXPECT_EQ(back.peak_resident_bytes, n.peak_resident_bytes);
  EXPECT_EQ(back.cache_capacity, n.cache_capacity);
  EXPECT_EQ(back.evictions, n.evictions);
}

TEST(ReportWire, RouterCountersRoundTrip) {
  const nodes::RouterCounters c = router_counters();
  const Bytes bytes = encoded([&](WireWriter& w) { nodes::put_router_counters(w, c); });
  // Each route: its id, its kind (one byte), its counted nodes.
  const std::size_t routes = 8 + (8 + 1 + 8 + 3 * 4) + (8 + 1 + 8) + (8 + 1 + 8 + 4);
  EXPECT_EQ(bytes.size(), 4 * 8 + 4 + 8 + 2 * sizeof(nodes::LinkCounters) + sizeof(c.hops) +
                              sizeof(c.hops_by_kind) + routes);
  WireWriter layout;
  for (std::uint64_t x : {c.injected, c.forwarded, c.delivered, c.in_place}) layout.put(x);
  layout.put(c.peak_pending);
  layout.put_vector(c.sent);
  layout.put(c.hops);
  layout.put(c.hops_by_kind);
  layout.put<std::uint64_t>(c.routes.size());
  for (const nodes::RouteRecord& route : c.routes) {
    layout.put(route.id);
    layout.put(route.kind);
    layout.put_vector(route.route);
  }
  EXPECT_EQ(bytes, layout.take());
  WireReader r(bytes);
  const nodes::RouterCounters back = nodes::get_router_counters(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.injected, c.injected);
  EXPECT_EQ(back.forwarded, c.forwarded);
  EXPECT_EQ(back.delivered, c.delivered);
  EXPECT_EQ(back.in_place, c.in_place);
  EXPECT_EQ(back.peak_pending, c.peak_pending);
  ASSERT_EQ(back.sent.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(same_bytes(back.sent[i], c.sent[i]));
  expect_same(back.hops, c.hops);
  for (std::size_t k = 0; k < c.hops_by_kind.size(); ++k) expect_same(back.hops_by_kind[k], c.hops_by_kind[k]);
  ASSERT_EQ(back.routes.size(), c.routes.size());
  for (std::size_t i = 0; i < c.routes.size(); ++i) {
    EXPECT_EQ(back.routes[i].id, c.routes[i].id);
    EXPECT_EQ(back.routes[i].kind, c.routes[i].kind);
    EXPECT_EQ(back.routes[i].route, c.routes[i].route);
  }
}

TEST(ReportWire, RankReportRoundTripsWithItsThreads) {
  const nodes::RankReport k = rank_report();
  const Bytes bytes = encoded([&](WireWriter& w) { nodes::put_rank_report(w, k, threads); });
  EXPECT_EQ(bytes.size(), 4 + 4 + 4 + 4 + sizeof(k.bridge) + 8 + 8 + 8 + 8 + 2 * sizeof(csp::ThreadUse));
  WireWriter layout;
  layout.put(k.rank);
  layout.put(k.first_node);
  layout.put(k.node_count);
  layout.put(k.threads);
  layout.put(k.bridge);
  layout.put(k.wall_seconds);
  layout.put(k.cpu_seconds);
  layout.put(k.peak_scene_bytes);
  layout.put_vector(threads);
  EXPECT_EQ(bytes, layout.take());
  WireReader r(bytes);
  std::vector<csp::ThreadUse> back_threads{patterned<csp::ThreadUse>(7)};  // replaced, not added to
  const nodes::RankReport back = nodes::get_rank_report(r, back_threads);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.rank, k.rank);
  EXPECT_EQ(back.first_node, k.first_node);
  EXPECT_EQ(back.node_count, k.node_count);
  EXPECT_EQ(back.threads, k.threads);
  EXPECT_TRUE(same_bytes(back.bridge, k.bridge));
  EXPECT_EQ(back.wall_seconds, k.wall_seconds);
  EXPECT_EQ(back.cpu_seconds, k.cpu_seconds);
  EXPECT_EQ(back.peak_scene_bytes, k.peak_scene_bytes);
  ASSERT_EQ(back_threads.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(same_bytes(back_threads[i], threads[i]));
}

// As a rank sends them to rank 0 after the run: its report, then each
// node's report and router counters; a cut anywhere is refused.
// A node's recorded events, as a rank sends them to rank 0 after its
// report in a recorded run: every list and count comes back, times and all.
TEST(ReportWire, NodeLogRoundTripsAndMovesOntoAnotherClock) {
  nodes::NodeLog log;
  log.injected = {{0x1122334455667788, 0.25, 7, 1030, 4}};
  log.departed = {{9, 0.5, 3, 1}, {10, 0.75, 1, 0}};
  log.arrived = {{9, 0.625, 0, 2}};
  log.delivered = {{11, 1.5, 3}};
  log.unrecorded[4] = 12;
  log.unrecorded_hops = 30;
  log.fetches = {{0.125, 0.375, 77, 1}};
  log.serves = {{0.25, 0.3125, 78, 5}};
  log.hits = {{0.875, 400, 1}};
  log.unrecorded_fetches = 3;
  log.unrecorded_serves = 2;
  const Bytes bytes = encoded([&](WireWriter& w) { nodes::put_node_log(w, log); });
  WireReader r(bytes);
  nodes::NodeLog back = nodes::get_node_log(r);
  EXPECT_TRUE(r.done());
  ASSERT_EQ(back.injected.size(), 1u);
  EXPECT_EQ(back.injected[0].id, 0x1122334455667788u);
  EXPECT_EQ(back.injected[0].destination, 7u);
  EXPECT_EQ(back.injected[0].bytes, 1030u);
  ASSERT_EQ(back.departed.size(), 2u);
  EXPECT_EQ(back.departed[1].id, 10u);
  EXPECT_EQ(back.departed[0].queue, 3u);
  ASSERT_EQ(back.arrived.size(), 1u);
  EXPECT_EQ(back.arrived[0].hop, 2u);
  ASSERT_EQ(back.delivered.size(), 1u);
  EXPECT_EQ(back.delivered[0].hops, 3u);
  EXPECT_EQ(back.unrecorded, log.unrecorded);
  EXPECT_EQ(back.unrecorded_hops, 30u);
  ASSERT_EQ(back.fetches.size(), 1u);
  EXPECT_EQ(back.fetches[0].page, 77u);
  ASSERT_EQ(back.serves.size(), 1u);
  EXPECT_EQ(back.serves[0].to, 5u);
  ASSERT_EQ(back.hits.size(), 1u);
  EXPECT_EQ(back.hits[0].hits, 400u);
  EXPECT_EQ(back.unrecorded_fetches, 3u);
  EXPECT_EQ(back.unrecorded_serves, 2u);
  nodes::shift_times(back, 2.0);
  EXPECT_EQ(back.injected[0].time, 2.25);
  EXPECT_EQ(back.departed[1].time, 2.75);
  EXPECT_EQ(back.arrived[0].time, 2.625);
  EXPECT_EQ(back.delivered[0].time, 3.5);
  EXPECT_EQ(back.fetches[0].start, 2.125);
  EXPECT_EQ(back.fetches[0].end, 2.375);
  EXPECT_EQ(back.serves[0].end, 2.3125);
  EXPECT_EQ(back.hits[0].time, 2.875);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) {
    WireReader cut(b);
    nodes::get_node_log(cut);
  });
}

TEST(ReportWire, AReportMessageCutShortIsRefused) {
  const nodes::RankReport k = rank_report();
  const nodes::NodeReport n = node_report();
  const nodes::RouterCounters c = router_counters();
  const Bytes message = encoded([&](WireWriter& w) {
    nodes::put_rank_report(w, k, threads);
    nodes::put_node_report(w, n);
    nodes::put_router_counters(w, c);
  });
  const auto read_all = [](std::span<const std::byte> b) {
    WireReader r(b);
    std::vector<csp::ThreadUse> got;
    nodes::get_rank_report(r, got);
    nodes::get_node_report(r);
    nodes::get_router_counters(r);
    return r.done();
  };
  EXPECT_TRUE(read_all(message));
  expect_prefixes_refused(message, read_all);
  const tracer::DatabaseHeader h = header();
  const Bytes header_bytes = encoded([&](WireWriter& w) { nodes::put_header(w, h); });
  expect_prefixes_refused(header_bytes, [](std::span<const std::byte> b) {
    WireReader r(b);
    nodes::get_header(r);
  });
}

TEST(ReportWire, ACountBeyondTheMessageIsRefused) {
  nodes::RouterCounters c;
  c.routes = {{1, 2, {3}}};
  Bytes bytes = encoded([&](WireWriter& w) { nodes::put_router_counters(w, c); });
  // The routes' count stands before the one route (8 + 1 + 8 + 4 bytes) at the end.
  const Bytes huge = wire_test::raw(std::numeric_limits<std::uint64_t>::max());
  wire_test::overwrite(bytes, bytes.size() - 21 - 8, huge);
  WireReader r(bytes);
  EXPECT_THROW(nodes::get_router_counters(r), std::runtime_error);
  nodes::NodeReport n;
  n.work.spans.resize(1);
  Bytes node = encoded([&](WireWriter& w) { nodes::put_node_report(w, n); });
  // The spans' count: before one span and the 8 + 8 + 4 + 8 bytes after it.
  wire_test::overwrite(node, node.size() - 28 - sizeof(nodes::TileSpan) - 8, huge);
  WireReader rn(node);
  EXPECT_THROW(nodes::get_node_report(rn), std::runtime_error);
}

}  // namespace
