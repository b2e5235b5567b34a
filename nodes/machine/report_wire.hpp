// The byte form of what ranks of a split machine send one another outside
// the network: the database header (rank 0 to every rank, before the run)
// and the reports of a rank's nodes and routers (to rank 0, after it).
// Encode and decode are inverses field by field; a decoder throws
// std::runtime_error (transport.hpp) on a message too short for its fields.
#pragma once

#include <vector>

#include "csp/runtime.hpp"
#include "nodes/ranks/transport.hpp"
#include "tracer/database.hpp"

namespace nodes {

struct NodeReport;
struct RankReport;
struct RouterCounters;

void put_header(WireWriter& w, const tracer::DatabaseHeader& header);
tracer::DatabaseHeader get_header(WireReader& r);

void put_node_report(WireWriter& w, const NodeReport& report);
NodeReport get_node_report(WireReader& r);

void put_router_counters(WireWriter& w, const RouterCounters& counters);
RouterCounters get_router_counters(WireReader& r);

void put_rank_report(WireWriter& w, const RankReport& report, const std::vector<csp::ThreadUse>& threads);
RankReport get_rank_report(WireReader& r, std::vector<csp::ThreadUse>& threads);

}  // namespace nodes
