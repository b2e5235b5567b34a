// Channel dependency graph construction and cycle search (iterative DFS, so
// a 4096-node ring does not overflow the call stack).
#include "topology/deadlock.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace topology {
namespace {

// Dense numbering of (node, port, class) and its inverse.
class ChannelIndex {
 public:
  ChannelIndex(const Topology& t, unsigned classes) : topology_(t), classes_(classes) {
    first_port_.reserve(t.size() + 1);
    std::size_t total = 0;
    for (NodeId n = 0; n < t.size(); ++n) {
      first_port_.push_back(total);
      total += t.degree(n);
    }
    first_port_.push_back(total);
  }

  std::size_t size() const { return first_port_.back() * classes_; }

  std::uint32_t id(NodeId n, Hop hop) const {
    if (hop.buffer_class >= classes_)
      throw std::logic_error("routing used buffer class " + std::to_string(hop.buffer_class) +
                             " of only " + std::to_string(classes_));
    return static_cast<std::uint32_t>((first_port_[n] + hop.port) * classes_ + hop.buffer_class);
  }

  VirtualChannel channel(std::uint32_t id) const {
    const std::size_t link = id / classes_;
    const auto node = static_cast<NodeId>(
        std::upper_bound(first_port_.begin(), first_port_.end(), link) - first_port_.begin() - 1);
    const auto port = static_cast<Port>(link - first_port_[node]);
    return VirtualChannel{node, topology_.neighbour(node, port), port,
                          static_cast<std::uint8_t>(id % classes_)};
  }

 private:
  const Topology& topology_;
  unsigned classes_;
  std::vector<std::size_t> first_port_;
};

// Compressed adjacency: successors of v are targets[start[v] .. start[v+1]).
struct Graph {
  std::vector<std::size_t> start;
  std::vector<std::uint32_t> targets;
};

Graph build_graph(const Topology& t, const RoutingFunction& route, const ChannelIndex& index) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (NodeId at = 0; at < t.size(); ++at) {
    for (NodeId dst = 0; dst < t.size(); ++dst) {
      if (at == dst) continue;
      const Hop first = route(at, dst);
      const NodeId next = t.neighbour(at, first.port);
      if (next == dst) continue;
      edges.emplace_back(index.id(at, first), index.id(next, route(next, dst)));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Graph g;
  g.start.assign(index.size() + 1, 0);
  for (const auto& e : edges) ++g.start[e.first + 1];
  for (std::size_t v = 0; v < index.size(); ++v) g.start[v + 1] += g.start[v];
  g.targets.reserve(edges.size());
  for (const auto& e : edges) g.targets.push_back(e.second);
  return g;
}

// Returns the vertices of one cycle, or nothing if the graph is acyclic.
std::vector<std::uint32_t> find_cycle(const Graph& g) {
  enum : std::uint8_t { white, grey, black };
  const std::size_t n = g.start.size() - 1;
  std::vector<std::uint8_t> colour(n, white);
  std::vector<std::pair<std::uint32_t, std::size_t>> stack;  // vertex, next edge
  for (std::uint32_t root = 0; root < n; ++root) {
    if (colour[root] != white) continue;
    stack.emplace_back(root, g.start[root]);
    colour[root] = grey;
    while (!stack.empty()) {
      auto& [v, edge] = stack.back();
      if (edge == g.start[v + 1]) {
        colour[v] = black;
        stack.pop_back();
        continue;
      }
      const std::uint32_t w = g.targets[edge++];
      if (colour[w] == grey) {
        std::vector<std::uint32_t> cycle;
        auto it = std::find_if(stack.begin(), stack.end(), [w](auto& f) { return f.first == w; });
        for (; it != stack.end(); ++it) cycle.push_back(it->first);
        return cycle;
      }
      if (colour[w] == white) {
        colour[w] = grey;
        stack.emplace_back(w, g.start[w]);
      }
    }
  }
  return {};
}

}  // namespace

std::string DependencyAnalysis::describe() const {
  if (acyclic)
    return "acyclic: " + std::to_string(channels) + " channels, " +
           std::to_string(dependencies) + " dependencies";
  std::string s = "cycle of " + std::to_string(cycle.size()) + " channels:";
  for (std::size_t i = 0; i < cycle.size(); ++i) {
    const auto& c = cycle[i];
    s += (i ? ", " : " ") + std::to_string(c.from) + "->" + std::to_string(c.to) + " [" +
         std::to_string(c.buffer_class) + "]";
  }
  return s;
}

DependencyAnalysis analyse_dependencies(const Topology& topology, const RoutingFunction& route,
                                        unsigned buffer_classes) {
  const ChannelIndex index(topology, buffer_classes);
  const Graph g = build_graph(topology, route, index);
  DependencyAnalysis result;
  result.channels = index.size();
  result.dependencies = g.targets.size();
  for (std::uint32_t v : find_cycle(g)) result.cycle.push_back(index.channel(v));
  result.acyclic = result.cycle.empty();
  return result;
}

DependencyAnalysis analyse_deadlock_free(const Topology& topology) {
  return analyse_dependencies(
      topology, [&](NodeId a, NodeId t) { return topology.next_hop(a, t); },
      topology.buffer_classes());
}

DependencyAnalysis analyse_naive(const Topology& topology) {
  return analyse_dependencies(
      topology, [&](NodeId a, NodeId t) { return topology.naive_next_hop(a, t); }, 1);
}

}  // namespace topology
