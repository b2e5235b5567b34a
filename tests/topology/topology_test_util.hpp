// Shared fixtures for the topology tests: a representative set of machines
// of every kind and a breadth-first distance oracle.
#pragma once

#include <queue>
#include <vector>

#include "topology/topology.hpp"

namespace topology::testing {

inline std::vector<Topology> sample_topologies(bool include_large) {
  std::vector<Topology> out;
  for (unsigned d = 0; d <= (include_large ? 10u : 6u); ++d) out.push_back(Topology::hypercube(d));
  for (auto [w, h] : std::vector<std::pair<unsigned, unsigned>>{
           {1, 1}, {1, 5}, {5, 1}, {2, 2}, {3, 4}, {7, 5}, {8, 8}, {2, 3}, {4, 4}, {5, 4}, {1, 7}}) {
    out.push_back(Topology::mesh(w, h));
    out.push_back(Topology::torus(w, h));
  }
  for (unsigned n : {1u, 2u, 3u, 4u, 5u, 16u, 17u, 64u}) {
    out.push_back(Topology::ring(n));
    out.push_back(Topology::complete(n));
  }
  if (include_large) {
    out.push_back(Topology::mesh(32, 32));
    out.push_back(Topology::torus(32, 32));
    out.push_back(Topology::ring(1024));
    out.push_back(Topology::complete(1024));
  }
  return out;
}

inline std::vector<unsigned> bfs_distances(const Topology& t, NodeId source) {
  std::vector<unsigned> dist(t.size(), ~0u);
  std::queue<NodeId> queue;
  dist[source] = 0;
  queue.push(source);
  while (!queue.empty()) {
    const NodeId n = queue.front();
    queue.pop();
    for (NodeId m : t.neighbours(n))
      if (dist[m] == ~0u) {
        dist[m] = dist[n] + 1;
        queue.push(m);
      }
  }
  return dist;
}

}  // namespace topology::testing
