// Parsing of topology specifications given on a command line:
//   "hypercube:6"  "mesh:8x8"  "torus:4x4"  "ring:64"  "complete:16"
// or a bare kind ("mesh") together with a node count (N), for which
// a mesh or torus takes the squarest W x H with W >= H.
//
// Invariant: every failure is a std::invalid_argument whose what() is one
// line naming the problem (unknown kind, malformed size, a hypercube that is
// not a power of two, 0 or more than max_nodes nodes, a size that disagrees
// with a node count). A result always satisfies 1 <= size() <= max_nodes.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>

#include "topology/topology.hpp"

namespace topology {

Topology parse_topology(std::string_view spec, std::optional<std::size_t> nodes = std::nullopt);

// The squarest factorisation W x H = nodes with W >= H.
std::pair<unsigned, unsigned> squarest_grid(std::size_t nodes);

}  // namespace topology
