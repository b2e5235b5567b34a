// Channel dependency analysis (Dally & Seitz, 1987): a deterministic routing
// function on a network of bounded buffers is deadlock-free if the graph whose
// vertices are the (link, buffer class) channels, with an edge c1 -> c2
// whenever some packet may hold c1 while waiting for c2, is acyclic.
//
// Because our routing functions depend only on (current node, destination),
// the edges are exactly: for every node a and destination t != a, the channel
// a takes towards t, followed by the channel its neighbour takes towards t
// (unless the neighbour is t). That is N^2 route look-ups, not N^3.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "topology/topology.hpp"

namespace topology {

// One direction of one link, in one buffer class.
struct VirtualChannel {
  NodeId from = 0;
  NodeId to = 0;
  Port port = 0;  // port of `from`
  std::uint8_t buffer_class = 0;
  friend bool operator==(const VirtualChannel&, const VirtualChannel&) = default;
};

using RoutingFunction = std::function<Hop(NodeId at, NodeId destination)>;

struct DependencyAnalysis {
  std::size_t channels = 0;      // vertices: directed links x buffer classes
  std::size_t dependencies = 0;  // distinct edges
  bool acyclic = true;
  std::vector<VirtualChannel> cycle;  // evidence when cyclic: c0 -> c1 -> ... -> c0

  // e.g. "cycle of 4 channels: 0->1 [0], 1->2 [0], 2->3 [0], 3->0 [0]"
  std::string describe() const;
};

DependencyAnalysis analyse_dependencies(const Topology& topology, const RoutingFunction& route,
                                        unsigned buffer_classes);

// The routing the network uses (next_hop with its buffer classes).
DependencyAnalysis analyse_deadlock_free(const Topology& topology);
// The same paths in a single buffer class.
DependencyAnalysis analyse_naive(const Topology& topology);

}  // namespace topology
