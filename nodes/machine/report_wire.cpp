// The header and the reports to and from bytes by their field lists; see report_wire.hpp.
#include "nodes/machine/report_wire.hpp"

#include "nodes/machine/node_report.hpp"
#include "nodes/machine/recorder.hpp"

namespace nodes {

void put_header(WireWriter& w, const tracer::DatabaseHeader& h) { put_fields(w, h); }

tracer::DatabaseHeader get_header(WireReader& r) { return get_fields<tracer::DatabaseHeader>(r); }

void put_node_report(WireWriter& w, const NodeReport& n) { put_fields(w, n); }

NodeReport get_node_report(WireReader& r) { return get_fields<NodeReport>(r); }

void put_node_log(WireWriter& w, const NodeLog& log) { put_fields(w, log); }

NodeLog get_node_log(WireReader& r) { return get_fields<NodeLog>(r); }

void put_router_counters(WireWriter& w, const RouterCounters& c) { put_fields(w, c); }

RouterCounters get_router_counters(WireReader& r) { return get_fields<RouterCounters>(r); }

void put_rank_report(WireWriter& w, const RankReport& k, const std::vector<csp::ThreadUse>& threads) {
  put_fields(w, k);
  put_fields(w, threads);
}

RankReport get_rank_report(WireReader& r, std::vector<csp::ThreadUse>& threads) {
  auto k = get_fields<RankReport>(r);
  get_fields(r, threads);
  return k;
}

}  // namespace nodes
