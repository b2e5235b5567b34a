// The byte form of what ranks of a split machine send one another outside
// the network: the database header (rank 0 to every rank, before the run)
// and the reports of a rank's nodes and routers, with their recorded events
// in a recorded run (to rank 0, after it).
// Each format is the one field list below, in wire order, that both encode
// and decode go by (wire_fields.hpp says how a field travels), so they are
// inverses field by field; a decoder throws std::runtime_error
// (transport.hpp) on a message too short for its fields.
#pragma once

#include <vector>

#include "csp/runtime.hpp"
#include "nodes/ranks/transport.hpp"
#include "nodes/ranks/wire_fields.hpp"
#include "tracer/database.hpp"

namespace nodes {

struct NodeLog;
struct NodeReport;
struct RankReport;
struct RouteRecord;
struct RouterCounters;
struct WorkerCounters;

template <class V>
void wire_fields(V& v, WireView<tracer::DatabaseHeader> auto& h) {
  v(h.scene_name);
  v(h.camera);
  v(h.background);
  v(h.lights);
  v(h.page_size);
  v(h.page_shift);
  v(h.page_count);
  v(h.sections);
  v(h.accel);
  v(h.bounds);
  v(h.bvh_root);
  v(h.bvh_depth);
  v(h.grid_dims);
  v(h.epsilon);
  v(h.polygon_count);
  v(h.object_count);
  v(h.primitive_count);
}

template <class V>
void wire_fields(V& v, WireView<WorkerCounters> auto& w) {
  v(w.items);
  v(w.tiles);
  v(w.rays);
  v(w.spans);
}

template <class V>
void wire_fields(V& v, WireView<NodeReport> auto& n) {
  v(n.svm);
  v(n.served);
  v(n.work);
  v(n.own_bytes);
  v(n.peak_resident_bytes);
  v(n.cache_capacity);
  v(n.evictions);
}

template <class V>
void wire_fields(V& v, WireView<RouteRecord> auto& route) {
  v(route.id);
  v(route.kind);
  v(route.route);
}

template <class V>
void wire_fields(V& v, WireView<RouterCounters> auto& c) {
  v(c.injected);
  v(c.forwarded);
  v(c.delivered);
  v(c.in_place);
  v(c.peak_pending);
  v(c.sent);
  v(c.hops);
  v(c.hops_by_kind);
  v(c.routes);
}

// A node's recorded events (recorder.hpp), after its report when the run
// is recorded; the events travel as their bytes, times on the sending
// rank's clock.
template <class V>
void wire_fields(V& v, WireView<NodeLog> auto& log) {
  v(log.injected);
  v(log.departed);
  v(log.arrived);
  v(log.delivered);
  v(log.unrecorded);
  v(log.unrecorded_hops);
  v(log.fetches);
  v(log.serves);
  v(log.hits);
  v(log.unrecorded_fetches);
  v(log.unrecorded_serves);
}

// Followed on the wire by the rank's host threads (put_rank_report).
template <class V>
void wire_fields(V& v, WireView<RankReport> auto& k) {
  v(k.rank);
  v(k.first_node);
  v(k.node_count);
  v(k.threads);
  v(k.bridge);
  v(k.wall_seconds);
  v(k.cpu_seconds);
  v(k.peak_scene_bytes);
}

void put_header(WireWriter& w, const tracer::DatabaseHeader& header);
tracer::DatabaseHeader get_header(WireReader& r);

void put_node_report(WireWriter& w, const NodeReport& report);
NodeReport get_node_report(WireReader& r);

void put_node_log(WireWriter& w, const NodeLog& log);
NodeLog get_node_log(WireReader& r);

void put_router_counters(WireWriter& w, const RouterCounters& counters);
RouterCounters get_router_counters(WireReader& r);

void put_rank_report(WireWriter& w, const RankReport& report, const std::vector<csp::ThreadUse>& threads);
RankReport get_rank_report(WireReader& r, std::vector<csp::ThreadUse>& threads);

}  // namespace nodes
