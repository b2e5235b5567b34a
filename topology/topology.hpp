// Interconnection graphs of a distributed-memory machine: hypercube, 2-D mesh,
// 2-D torus, bidirectional ring and complete graph, as small value types.
// Invariants:
// - Nodes are 0..size()-1; size() is between 1 and max_nodes.
// - Ports of node n are dense, 0..degree(n)-1, and neighbour(n, p) names the
//   node at the other end. Links are symmetric (a port to m on n implies a
//   port to n on m) and never loop back to n itself; a dimension of extent 2
//   on a torus gives one link, not two.
// - next_hop(from, to) is a deterministic, minimal routing function of the
//   current node and the destination only (never of the source), so a route
//   is the same whoever sent the packet. Its buffer class keeps the channel
//   dependency graph acyclic (see deadlock.hpp); naive_next_hop takes the
//   same path with a single class, for comparison.
// - total_distance() and diameter() are computed in closed form; tests check
//   them against breadth-first search.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace topology {

using NodeId = std::uint32_t;
using Port = std::uint32_t;

enum class Kind : std::uint8_t { hypercube, mesh, torus, ring, complete };

// The largest machine we build: 4096 processors (a 12-cube).
inline constexpr std::size_t max_nodes = 4096;

// One hop of a route: which port to leave by and in which buffer class
// (virtual channel) the packet waits for that link.
struct Hop {
  Port port = 0;
  std::uint8_t buffer_class = 0;
  friend bool operator==(const Hop&, const Hop&) = default;
};

class Topology {
 public:
  // Factories; each throws std::invalid_argument for an impossible size.
  static Topology hypercube(unsigned dimension);
  static Topology mesh(unsigned width, unsigned height);
  static Topology torus(unsigned width, unsigned height);
  static Topology ring(unsigned nodes);
  static Topology complete(unsigned nodes);

  Kind kind() const { return kind_; }
  std::size_t size() const { return static_cast<std::size_t>(width_) * height_; }
  unsigned width() const { return width_; }    // hypercube: 2^d; ring/complete: N
  unsigned height() const { return height_; }  // 1 except for mesh/torus
  unsigned dimension() const { return dimension_; }  // hypercube only; else 0
  std::string spec() const;  // canonical form accepted by parse_topology

  unsigned degree(NodeId n) const;
  NodeId neighbour(NodeId n, Port p) const;
  std::vector<NodeId> neighbours(NodeId n) const;  // index = port
  Port port_to(NodeId n, NodeId m) const;          // m must be a neighbour of n

  // Coordinates for drawing: hypercube bits (bit i at index i), mesh/torus
  // {x, y}, ring/complete {index}.
  std::vector<unsigned> coordinates(NodeId n) const;

  unsigned distance(NodeId a, NodeId b) const;
  unsigned diameter() const;
  // Sum of distance(a, b) over all ordered pairs, exact.
  std::uint64_t total_distance() const;
  // Mean distance over ordered pairs of distinct nodes (0 for one node).
  double average_distance() const;

  // Deadlock-free deterministic minimal routing; requires from != to.
  Hop next_hop(NodeId from, NodeId to) const;
  // The same path, every hop in buffer class 0 (cyclic on rings and tori).
  Hop naive_next_hop(NodeId from, NodeId to) const;
  // Number of buffer classes next_hop uses (1, or 2 for wrapped dimensions).
  unsigned buffer_classes() const;

 private:
  Topology(Kind kind, unsigned width, unsigned height, unsigned dimension);

  // Mesh/torus: the up-to-four candidate neighbours in port order
  // (+x, -x, +y, -y), with absent or duplicate ones removed.
  std::vector<NodeId> grid_neighbours(NodeId n) const;
  Hop grid_hop(NodeId from, NodeId to) const;

  Kind kind_;
  unsigned width_;
  unsigned height_;
  unsigned dimension_;
};

const char* kind_name(Kind kind);

// Shortest direction round a ring of `extent` positions from a to b:
// +1, -1 (ties go +1) or 0 when a == b.
int ring_direction(unsigned a, unsigned b, unsigned extent);
unsigned ring_distance(unsigned a, unsigned b, unsigned extent);

}  // namespace topology
