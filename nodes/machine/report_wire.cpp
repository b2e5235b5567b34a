// Field-by-field encoding of the header and the reports; see report_wire.hpp.
#include "nodes/machine/report_wire.hpp"

#include "nodes/machine/node_report.hpp"

namespace nodes {

void put_header(WireWriter& w, const tracer::DatabaseHeader& h) {
  w.put_string(h.scene_name);
  w.put(h.camera);
  w.put(h.background);
  w.put_vector(h.lights);
  w.put(h.page_size);
  w.put(h.page_shift);
  w.put(h.page_count);
  for (const auto& section : h.sections) w.put(section);
  w.put(h.accel);
  w.put(h.bounds);
  w.put(h.bvh_root);
  w.put(h.bvh_depth);
  for (int d : h.grid_dims) w.put(d);
  w.put(h.epsilon);
  w.put(h.polygon_count);
  w.put(h.object_count);
  w.put(h.primitive_count);
}

tracer::DatabaseHeader get_header(WireReader& r) {
  tracer::DatabaseHeader h;
  h.scene_name = r.get_string();
  h.camera = r.get<tracer::Camera>();
  h.background = r.get<tracer::Color>();
  h.lights = r.get_vector<tracer::LightRecord>();
  h.page_size = r.get<std::uint32_t>();
  h.page_shift = r.get<std::uint32_t>();
  h.page_count = r.get<std::uint32_t>();
  for (auto& section : h.sections) section = r.get<tracer::SectionLayout>();
  h.accel = r.get<tracer::Accel>();
  h.bounds = r.get<tracer::Box3f>();
  h.bvh_root = r.get<tracer::BvhNode>();
  h.bvh_depth = r.get<std::uint32_t>();
  for (int& d : h.grid_dims) d = r.get<int>();
  h.epsilon = r.get<float>();
  h.polygon_count = r.get<std::uint64_t>();
  h.object_count = r.get<std::uint64_t>();
  h.primitive_count = r.get<std::uint64_t>();
  return h;
}

void put_node_report(WireWriter& w, const NodeReport& n) {
  w.put(n.svm);
  w.put(n.served);
  w.put(n.work.items);
  w.put(n.work.tiles);
  w.put(n.work.rays);
  w.put_vector(n.work.spans);
  w.put(n.own_bytes);
  w.put(n.peak_resident_bytes);
  w.put(n.cache_capacity);
  w.put(n.evictions);
}

NodeReport get_node_report(WireReader& r) {
  NodeReport n;
  n.svm = r.get<SvmStats>();
  n.served = r.get<ServerCounters>();
  n.work.items = r.get<std::uint64_t>();
  n.work.tiles = r.get<std::uint64_t>();
  n.work.rays = r.get<tracer::RayStats>();
  n.work.spans = r.get_vector<TileSpan>();
  n.own_bytes = r.get<std::size_t>();
  n.peak_resident_bytes = r.get<std::size_t>();
  n.cache_capacity = r.get<std::uint32_t>();
  n.evictions = r.get<std::uint64_t>();
  return n;
}

void put_router_counters(WireWriter& w, const RouterCounters& c) {
  w.put(c.injected);
  w.put(c.forwarded);
  w.put(c.delivered);
  w.put(c.peak_pending);
  w.put_vector(c.sent);
  w.put(c.hops);
  w.put(c.hops_by_kind);
  w.put<std::uint64_t>(c.routes.size());
  for (const RouteRecord& route : c.routes) {
    w.put(route.id);
    w.put(route.kind);
    w.put_vector(route.route);
  }
}

RouterCounters get_router_counters(WireReader& r) {
  RouterCounters c;
  c.injected = r.get<std::uint64_t>();
  c.forwarded = r.get<std::uint64_t>();
  c.delivered = r.get<std::uint64_t>();
  c.peak_pending = r.get<std::uint32_t>();
  c.sent = r.get_vector<LinkCounters>();
  c.hops = r.get<HopSummary>();
  c.hops_by_kind = r.get<std::array<HopSummary, 256>>();
  const auto routes = r.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < routes; ++i) {
    RouteRecord route;
    route.id = r.get<std::uint64_t>();
    route.kind = r.get<std::uint8_t>();
    route.route = r.get_vector<NodeId>();
    c.routes.push_back(std::move(route));
  }
  return c;
}

void put_rank_report(WireWriter& w, const RankReport& k, const std::vector<csp::ThreadUse>& threads) {
  w.put(k.rank);
  w.put(k.first_node);
  w.put(k.node_count);
  w.put(k.threads);
  w.put(k.bridge);
  w.put(k.wall_seconds);
  w.put(k.cpu_seconds);
  w.put(k.peak_scene_bytes);
  w.put_vector(threads);
}

RankReport get_rank_report(WireReader& r, std::vector<csp::ThreadUse>& threads) {
  RankReport k;
  k.rank = r.get<int>();
  k.first_node = r.get<NodeId>();
  k.node_count = r.get<std::uint32_t>();
  k.threads = r.get<unsigned>();
  k.bridge = r.get<BridgeCounters>();
  k.wall_seconds = r.get<double>();
  k.cpu_seconds = r.get<double>();
  k.peak_scene_bytes = r.get<std::uint64_t>();
  threads = r.get_vector<csp::ThreadUse>();
  return k;
}

}  // namespace nodes
