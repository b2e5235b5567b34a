// How the farmer cuts the frame into work: a pure, deterministic plan of
// tiles (contiguous runs of items in scanline order), with no fibers.
//
// Items are pixels, or SPD corner samples in SPD procedure mode. A tile is a
// run along the scanline rather than a square because its result is one
// contiguous range (a compact message) and neighbouring rays along a row
// touch the same pages, which is what the cache needs.
//
// Invariants: every item is handed out exactly once over the plan's life;
// dynamic hands tiles of `grain` items in order to whoever asks; static gives
// worker (node, w) one fixed share: the frame in N equal parts, one per
// processor, each split among its workers; a worker's second request gets
// nothing.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "nodes/messages.hpp"

namespace nodes {

enum class Schedule { dynamic, static_split };

class WorkPlan {
 public:
  WorkPlan(std::uint32_t items, std::uint32_t grain, Schedule schedule, int nodes, int workers_per_node);

  // The next tile for worker `worker` of node `node`, or nullopt: stop.
  std::optional<Tile> next(int node, int worker);

  std::uint32_t items() const { return items_; }
  std::uint32_t handed_out() const { return handed_out_; }  // items given so far

 private:
  Tile static_share(int node, int worker) const;

  std::uint32_t items_;
  std::uint32_t grain_;
  Schedule schedule_;
  int nodes_;
  int workers_;
  std::uint32_t cursor_ = 0;       // dynamic: first item not yet handed out
  std::uint32_t handed_out_ = 0;
  std::vector<bool> share_taken_;  // static: per (node, worker)
};

}  // namespace nodes
