// How the farmer cuts the frame into work: a pure, deterministic plan of
// tiles (contiguous runs of item numbers), with no fibers.
//
// Items are pixels, or SPD corner samples in SPD procedure mode, numbered in
// the machine's pixel order (pixel_order.hpp). A tile is a run of numbers
// so that its result is one contiguous range (a compact message); the order
// decides whether that run is a piece of a row or a compact patch. The
// schedules (dynamic, static, affinity) are described at Schedule below.
//
// Invariants: every item is handed out exactly once over the plan's life
// (every worker asks at least once, and its first request takes from its own
// share); a share is always one contiguous run; dynamic tiles are at most
// `grain` items; the plan's answers depend only on the order of requests.
// A plan is used by the farmer alone and is not thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "nodes/machine/messages.hpp"

namespace nodes {

// How tiles are handed out:
//  - dynamic: tiles of `grain` items, in frame order, to whoever asks (the
//    paper's pixel farming);
//  - static: worker (node, w) gets one fixed share, the frame in N equal
//    parts, one per processor, each split among its workers; a worker's
//    second request gets nothing;
//  - affinity (Markatos and LeBlanc's affinity scheduling): each worker
//    starts on its static share and takes tiles from its front, each 1/P of
//    what is left of it (P workers, at least 16 parts, at least `grain`
//    items), so that a processor's rays stay near each other, its cache
//    holds their pages, and big early tiles save farming messages; a worker
//    whose share is used up takes 1/P of the largest share left, from its
//    back. A share whose owner has not asked yet keeps the owner's first
//    tile (see WorkPlan::stealable in work_plan.cpp).
enum class Schedule { dynamic, static_split, affinity };

// The schedule's name: dynamic, static or affinity.
const char* schedule_name(Schedule schedule);

class WorkPlan {
 public:
  WorkPlan(std::uint32_t items, std::uint32_t grain, Schedule schedule, int nodes, int workers_per_node);

  // The next tile for worker `worker` of node `node`, or nullopt: stop.
  std::optional<Tile> next(int node, int worker);

  std::uint32_t items() const { return items_; }
  std::uint32_t handed_out() const { return handed_out_; }  // items given so far
  std::uint32_t steals() const { return steals_; }          // affinity: tiles taken from another's share

  // Affinity tiles are 1/parts of what is left; at least this many parts,
  // so that a share on a small machine still comes back in pieces the
  // progress display and the balancing can use.
  static constexpr std::size_t min_affinity_parts = 16;

 private:
  Tile static_share(int node, int worker) const;

  std::uint32_t affinity_chunk(std::uint32_t left) const;
  Tile take_front(Tile& share, std::uint32_t most);
  Tile steal();
  std::uint32_t stealable(std::size_t share) const;

  std::uint32_t items_;
  std::uint32_t grain_;
  Schedule schedule_;
  int nodes_;
  int workers_;
  std::uint32_t cursor_ = 0;  // dynamic: first item not yet handed out
  std::uint32_t handed_out_ = 0;
  std::uint32_t steals_ = 0;
  std::vector<Tile> shares_;  // static and affinity: what is left of each worker's run
  std::vector<bool> started_;  // affinity: whether each worker has taken from its share
};

}  // namespace nodes
