// Tile plan of the farmer (see work_plan.hpp).
#include "nodes/work_plan.hpp"

#include <algorithm>
#include <stdexcept>

namespace nodes {

const char* schedule_name(Schedule schedule) {
  switch (schedule) {
    case Schedule::dynamic: return "dynamic";
    case Schedule::static_split: return "static";
    case Schedule::affinity: return "affinity";
  }
  return "?";
}

WorkPlan::WorkPlan(std::uint32_t items, std::uint32_t grain, Schedule schedule, int nodes, int workers_per_node)
    : items_(items), grain_(grain), schedule_(schedule), nodes_(nodes), workers_(workers_per_node) {
  if (grain == 0) throw std::invalid_argument("--grain must be at least 1");
  if (nodes < 1 || workers_per_node < 1) throw std::invalid_argument("work plan needs at least one worker");
  if (schedule == Schedule::dynamic) return;
  for (int n = 0; n < nodes; ++n)
    for (int w = 0; w < workers_per_node; ++w) shares_.push_back(static_share(n, w));
}

std::optional<Tile> WorkPlan::next(int node, int worker) {
  if (node < 0 || node >= nodes_ || worker < 0 || worker >= workers_)
    throw std::logic_error("work request from an unknown worker");
  Tile tile;
  if (schedule_ == Schedule::dynamic) {
    tile = {cursor_, std::min(grain_, items_ - cursor_)};
    cursor_ += tile.count;
  } else {
    Tile& share = shares_[static_cast<std::size_t>(node * workers_ + worker)];
    if (schedule_ == Schedule::static_split) tile = take_front(share, share.count);
    else if (share.count > 0) tile = take_front(share, affinity_chunk(share.count));
    else tile = steal();
  }
  if (tile.count == 0) return std::nullopt;
  handed_out_ += tile.count;
  return tile;
}

std::uint32_t WorkPlan::affinity_chunk(std::uint32_t left) const {
  const auto parts = static_cast<std::uint32_t>(std::max(shares_.size(), min_affinity_parts));
  return std::max(grain_, static_cast<std::uint32_t>((std::uint64_t{left} + parts - 1) / parts));
}

Tile WorkPlan::take_front(Tile& share, std::uint32_t most) {
  const Tile tile{share.first, std::min(most, share.count)};
  share.first += tile.count;
  share.count -= tile.count;
  return tile;
}

// A chunk off the back of the largest share left (the first such, for
// determinism): far from where its owner is working, and from the share that
// would otherwise finish last.
Tile WorkPlan::steal() {
  auto victim = std::max_element(shares_.begin(), shares_.end(),
                                 [](const Tile& a, const Tile& b) { return a.count < b.count; });
  if (victim->count == 0) return {};
  const std::uint32_t take = std::min(victim->count, affinity_chunk(victim->count));
  victim->count -= take;
  ++steals_;
  return {victim->first + victim->count, take};
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
