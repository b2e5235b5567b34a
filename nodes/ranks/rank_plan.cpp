// Block placement of nodes on ranks and the count of cut links.
#include "nodes/ranks/rank_plan.hpp"

#include <stdexcept>

namespace nodes {

RankPlan::RankPlan(const topology::Topology& topology, int ranks) : nodes_(topology.size()), ranks_(ranks) {
  if (ranks < 1 || static_cast<std::size_t>(ranks) > nodes_)
    throw std::invalid_argument("ranks: " + std::to_string(ranks) + " ranks for a machine of " +
                                std::to_string(nodes_) + (nodes_ == 1 ? " node" : " nodes") +
                                ": every rank needs at least one node");
  for (topology::NodeId n = 0; n < nodes_; ++n)
    for (topology::NodeId m : topology.neighbours(n))
      if (n < m && rank_of(n) != rank_of(m)) ++cut_links_;
}

topology::NodeId RankPlan::first(int rank) const {
  return static_cast<topology::NodeId>(static_cast<std::uint64_t>(rank) * nodes_ / static_cast<std::uint64_t>(ranks_));
}

std::size_t RankPlan::count(int rank) const { return (rank + 1 == ranks_ ? nodes_ : first(rank + 1)) - first(rank); }

// The largest r with first(r) <= node.
int RankPlan::rank_of(topology::NodeId node) const {
  auto r = static_cast<int>((static_cast<std::uint64_t>(node) * ranks_ + ranks_ - 1) / nodes_);
  if (r >= ranks_) r = ranks_ - 1;
  while (r > 0 && first(r) > node) --r;
  while (r + 1 < ranks_ && first(r + 1) <= node) ++r;
  return r;
}

std::string RankPlan::describe(int rank) const {
  const topology::NodeId a = first(rank);
  const std::size_t k = count(rank);
  if (k == 1) return "node " + std::to_string(a);
  return "nodes " + std::to_string(a) + "-" + std::to_string(a + k - 1);
}

}  // namespace nodes
