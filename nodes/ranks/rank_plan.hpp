// nodes::RankPlan: which OS process (rank) runs which processors when a
// machine is split over several, and which links the split cuts.
//
// Invariants:
//  - Rank r runs the contiguous block of nodes first(r) .. first(r)+count(r)-1,
//    first(r) = floor(r * N / R); every rank has at least one node (R <= N),
//    and block sizes differ by at most one.
//  - Contiguous numbers follow each topology's shape, so few links are cut:
//    a hypercube of 2^d nodes on 2^k ranks gives each rank a (d-k)-subcube
//    (the high address bits name the rank), meshes and tori (numbered row by
//    row) strips of rows when the ranks divide the rows (otherwise strips
//    that may end inside a row: balance first), rings arcs, complete graphs
//    blocks.
//  - cut_links() counts the undirected links whose two ends lie on
//    different ranks; only those carry packets between processes.
#pragma once

#include <cstddef>
#include <string>

#include "topology/topology.hpp"

namespace nodes {

class RankPlan {
 public:
  // Throws std::invalid_argument unless 1 <= ranks <= topology.size().
  RankPlan(const topology::Topology& topology, int ranks);

  int ranks() const { return ranks_; }
  std::size_t nodes() const { return nodes_; }
  int rank_of(topology::NodeId node) const;
  topology::NodeId first(int rank) const;
  std::size_t count(int rank) const;
  bool runs(int rank, topology::NodeId node) const { return rank_of(node) == rank; }
  std::size_t cut_links() const { return cut_links_; }
  // "nodes 0-7" / "node 3"
  std::string describe(int rank) const;

 private:
  std::size_t nodes_;
  int ranks_;
  std::size_t cut_links_ = 0;
};

}  // namespace nodes
