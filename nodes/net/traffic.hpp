// Synthetic traffic over the network, for the traffic example and the
// network benchmark: a plan of (source, destination) pairs from a classic
// pattern, and a driver that runs it on a fresh csp::Runtime.
//
// Processes per node: a sender writing its planned packets to injector(n),
// and a receiver reading port(n) until it has the number the plan sends to
// n (separate fibers, so the consumption assumption of router.hpp holds).
// The last receiver to finish calls Network::shutdown(). Packet ids are
// global and dense (0..total-1), in node order, so trace_routes N traces
// node 0's first packets.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "nodes/net/network.hpp"

namespace nodes {

enum class Pattern { uniform, all_to_one, all_to_all, bit_reversal };

// Throws std::invalid_argument naming the pattern if unknown.
Pattern parse_pattern(const std::string& name);

// plan[n] lists the destinations of node n's packets in sending order.
// uniform: `packets` random destinations per node (fixed seed);
// all_to_one: `packets` per node to node 0; all_to_all: every other node,
// max(1, packets / (N-1)) rounds; bit_reversal: `packets` per node to the
// node whose address bits are reversed (N must be a power of two).
using TrafficPlan = std::vector<std::vector<NodeId>>;
TrafficPlan make_plan(Pattern pattern, std::size_t nodes, std::size_t packets, std::uint32_t seed);

struct TrafficResult {
  NetworkStats stats;
  double seconds = 0;            // wall time of Runtime::run()
  std::uint64_t sent = 0;
  std::uint64_t delivered = 0;   // distinct ids received at the right node
  std::uint64_t misdelivered = 0;  // duplicates or wrong destination
};

TrafficResult run_traffic(const topology::Topology& topology, const TrafficPlan& plan,
                          const NetworkOptions& options, unsigned threads, std::size_t payload);

}  // namespace nodes
