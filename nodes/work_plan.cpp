// Tile plan of the farmer (see work_plan.hpp).
#include "nodes/work_plan.hpp"

#include <algorithm>
#include <stdexcept>

namespace nodes {

WorkPlan::WorkPlan(std::uint32_t items, std::uint32_t grain, Schedule schedule, int nodes, int workers_per_node)
    : items_(items), grain_(grain), schedule_(schedule), nodes_(nodes), workers_(workers_per_node) {
  if (grain == 0) throw std::invalid_argument("--grain must be at least 1");
  if (nodes < 1 || workers_per_node < 1) throw std::invalid_argument("work plan needs at least one worker");
  share_taken_.assign(static_cast<std::size_t>(nodes) * static_cast<std::size_t>(workers_per_node), false);
}

std::optional<Tile> WorkPlan::next(int node, int worker) {
  if (node < 0 || node >= nodes_ || worker < 0 || worker >= workers_)
    throw std::logic_error("work request from an unknown worker");
  Tile tile;
  if (schedule_ == Schedule::dynamic) {
    tile = {cursor_, std::min(grain_, items_ - cursor_)};
    cursor_ += tile.count;
  } else {
    const auto share = static_cast<std::size_t>(node * workers_ + worker);
    if (share_taken_[share]) return std::nullopt;
    share_taken_[share] = true;
    tile = static_share(node, worker);
  }
  if (tile.count == 0) return std::nullopt;
  handed_out_ += tile.count;
  return tile;
}

Tile WorkPlan::static_share(int node, int worker) const {
  // 64-bit products: items x nodes may exceed 32 bits.
  const auto part = [](std::uint64_t total, std::uint64_t parts, std::uint64_t i) {
    return static_cast<std::uint32_t>(total * i / parts);
  };
  const std::uint32_t node_first = part(items_, nodes_, node);
  const std::uint32_t node_items = part(items_, nodes_, node + 1) - node_first;
  const std::uint32_t first = node_first + part(node_items, workers_, worker);
  const std::uint32_t last = node_first + part(node_items, workers_, worker + 1);
  return {first, last - first};
}

}  // namespace nodes
