// Tile plan of the farmer (see work_plan.hpp).
#include "nodes/machine/work_plan.hpp"

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
  if (grain == 0) throw std::invalid_argument("grain must be at least 1");
  if (nodes < 1 || workers_per_node < 1) throw std::invalid_argument("work plan needs at least one worker");
  if (schedule == Schedule::dynamic) return;
  for (int n = 0; n < nodes; ++n)
    for (int w = 0; w < workers_per_node; ++w) shares_.push_back(static_share(n, w));
  started_.assign(shares_.size(), false);
}

std::optional<Tile> WorkPlan::next(int node, int worker) {
  if (node < 0 || node >= nodes_ || worker < 0 || worker >= workers_)
    throw std::logic_error("work request from an unknown worker");
  Tile tile;
  if (schedule_ == Schedule::dynamic) {
    tile = {cursor_, std::min(grain_, items_ - cursor_)};
    cursor_ += tile.count;
  } else {
    const auto me = static_cast<std::size_t>(node * workers_ + worker);
    Tile& share = shares_[me];
    if (schedule_ == Schedule::static_split) tile = take_front(share, share.count);
    else if (share.count > 0) tile = take_front(share, affinity_chunk(share.count));
    else tile = steal();
    if (schedule_ == Schedule::affinity) started_[me] = true;
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

// What a steal may take of share i: all of it once its owner has started,
// else all but the first tile its owner will take. Where shares are a tile
// or two (small frames on many processors), a worker asking ahead would
// otherwise take whole shares from processors that have not started, and
// leave them idle.
std::uint32_t WorkPlan::stealable(std::size_t i) const {
  const std::uint32_t count = shares_[i].count;
  if (started_[i]) return count;
  return count - std::min(count, affinity_chunk(count));
}

// A chunk off the back of the share with the most to steal (the first such,
// for determinism): far from where its owner is working, and from the share
// that would otherwise finish last. Nothing if no share has anything to
// spare: what is left are first tiles that their owners will take.
Tile WorkPlan::steal() {
  std::size_t victim = 0;
  std::uint32_t spare = 0;
  for (std::size_t i = 0; i < shares_.size(); ++i)
    if (const std::uint32_t n = stealable(i); n > spare) {
      victim = i;
      spare = n;
    }
  if (spare == 0) return {};
  Tile& share = shares_[victim];
  const std::uint32_t take = std::min(spare, affinity_chunk(share.count));
  share.count -= take;
  ++steals_;
  return {share.first + share.count, take};
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
