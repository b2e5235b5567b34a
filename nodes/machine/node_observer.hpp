// nodes::NodeObserver: what one node's pixel computers tell whoever watches
// the run, at the points where the watching happens: a page request about
// to leave and its page arrived (the miss path, make_page_fetch), and a tile
// traced, before its result leaves (PixelComputer). Virtual time charges the
// work there (timing.hpp) and the recorder logs it (recorder.hpp).
//
// A node has at most one observer; ObserverList makes one of several, each
// told in the order added. Hooks run on the worker's own fiber, on its
// node's thread, one worker's never nested: no lock. A hook may suspend the
// fiber (a charge advances its virtual clock).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "nodes/machine/svm.hpp"

namespace nodes {

class NodeObserver {
 public:
  virtual ~NodeObserver() = default;
  // Worker `worker` (0..k-1 on the node) misses on `page`: its request is about to leave.
  virtual void fetch_started(int /*worker*/, std::uint32_t /*page*/) {}
  // The page it asked for has arrived.
  virtual void fetch_ended(int /*worker*/, std::uint32_t /*page*/) {}
  // It has traced a tile; `memory` is what its page calls found so far.
  virtual void tile_done(int /*worker*/, const SvmStats& /*memory*/) {}
};

// Several observers as one, each hook passed on in the order they were added.
class ObserverList final : public NodeObserver {
 public:
  void add(std::unique_ptr<NodeObserver> observer) { observers_.push_back(std::move(observer)); }
  bool empty() const { return observers_.empty(); }

  void fetch_started(int worker, std::uint32_t page) override {
    for (const auto& o : observers_) o->fetch_started(worker, page);
  }
  void fetch_ended(int worker, std::uint32_t page) override {
    for (const auto& o : observers_) o->fetch_ended(worker, page);
  }
  void tile_done(int worker, const SvmStats& memory) override {
    for (const auto& o : observers_) o->tile_done(worker, memory);
  }

 private:
  std::vector<std::unique_ptr<NodeObserver>> observers_;
};

}  // namespace nodes
