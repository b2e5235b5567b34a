// A processor's share of the scene database: its own pages and an LRU
// cache of remote pages (the blocking part of the shared virtual memory is
// in svm.hpp). Pages are read-only while rendering, so a cached page never
// goes stale and is never invalidated. Invariants:
//  - entry_[p] says where page p lives on this node, in one array load:
//    >= 0 own page (its index among the own pages, which lie end to end in
//    one block), -1 not here, <= -2 cache slot (-2 - entry).
//  - the occupied slots form one list by use, most recent first: a hit and
//    an install (evicting from the back) take O(1).
//  - a slot named in install()'s `in_use` is never evicted; resident bytes
//    = own pages + occupied slots, at most capacity. A slot holds a copy,
//    or refers to a page another node of this process owns (Holding).
// A node's workers are fibers on one OS thread and run one at a time, and no
// member function suspends, so no lock is needed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace nodes {

enum class Distribution { modulo, block };

// Which node owns each page, and where in its own store the page sits.
class PagePlacement {
 public:
  PagePlacement(Distribution distribution, int nodes, std::uint32_t page_count);

  int owner(std::uint32_t page) const;
  std::uint32_t own_index(std::uint32_t page) const;      // index within owner's pages
  std::uint32_t page_of(int node, std::uint32_t index) const;  // inverse of own_index
  std::uint32_t own_count(int node) const;
  std::uint32_t page_count() const { return page_count_; }
  int nodes() const { return nodes_; }

 private:
  std::uint32_t block_first(int node) const;

  Distribution distribution_;
  int nodes_;
  std::uint32_t page_count_;
};

class NodeMemory {
 public:
  // own_pages: own_count(node) pages of page_size bytes, in own_index order;
  // each is freed as soon as it is copied into the node's own block, so the
  // host keeps no copy.
  NodeMemory(const PagePlacement& placement, int node, std::size_t page_size,
             std::vector<std::vector<std::byte>> own_pages, std::uint32_t cache_pages);
  // A memory whose own pages are placed later, each once by place_own and
  // all before any other use: their block is mapped but not yet written, so
  // a host that places pages one by one, freeing each, never holds two.
  NodeMemory(const PagePlacement& placement, int node, std::size_t page_size, std::uint32_t cache_pages);
  void place_own(std::uint32_t index, std::span<const std::byte> bytes);

  std::int32_t entry(std::uint32_t page) const { return entry_[page]; }
  static bool is_slot(std::int32_t entry) { return entry <= -2; }
  static int slot_of_entry(std::int32_t entry) { return -2 - entry; }

  const std::byte* own_page(std::int32_t index) const {
    return own_.get() + static_cast<std::size_t>(index) * page_size_;
  }
  const std::byte* slot_bytes(int slot) const { return uses_[static_cast<std::size_t>(slot)].data; }

  // The slot's bytes, making it the most recently used.
  const std::byte* use(int slot) {
    if (slot != front_) to_front(slot);
    return uses_[static_cast<std::size_t>(slot)].data;
  }

  // How a slot holds a page: a copy of the bytes, or the bytes themselves,
  // which must then stay unchanged and alive while the machine runs.
  enum class Holding { copy, reference };

  // Copies a fetched remote page into a free slot or the least recently
  // used one not named in `in_use`, and returns that slot, now the most
  // recently used. The node's workers each name in `in_use` the slot whose
  // bytes they are using, so one worker's install cannot pull them away from
  // another; the victim is found at most |in_use| + 1 steps from the back.
  // Throws std::logic_error if every slot is in use (cannot happen: see
  // docs/architecture.md, "The path of one page request").
  int install(std::uint32_t page, std::span<const std::byte> bytes, std::span<const int> in_use = {},
              Holding holding = Holding::copy);

  // Miss coalescing: begin_fetch is true for the first worker to miss on a
  // page (it fetches); later ones add_waiter and are woken by the fetcher
  // with the list end_fetch returns.
  bool begin_fetch(std::uint32_t page);
  void add_waiter(std::uint32_t page, int worker);
  std::vector<int> end_fetch(std::uint32_t page);

  std::uint32_t cache_capacity() const { return capacity_; }
  std::size_t page_size() const { return page_size_; }
  std::size_t own_bytes() const { return own_count_ * page_size_; }
  std::size_t resident_bytes() const { return (own_count_ + slots_.size()) * page_size_; }
  std::uint64_t evictions() const { return evictions_; }

 private:
  struct Slot {
    std::unique_ptr<std::byte[]> bytes;  // page_size_ bytes, allocated on the first copy
    std::uint32_t page = 0;
  };
  // What a hit touches, apart (16 bytes a slot): the use list links slots
  // by index; a hit on the most recent slot changes nothing, any other hit
  // moves its slot to the front, and an install into a full cache evicts
  // from the back.
  struct Use {
    const std::byte* data = nullptr;  // the page: the slot's bytes, or the owner's (Holding::reference)
    int newer = -1;  // the slot used just after this one; -1: this is the front
    int older = -1;  // the slot used just before; -1: this is the back
  };

  int take_slot(std::span<const int> in_use);
  void push_front(int slot) {
    Use& s = uses_[static_cast<std::size_t>(slot)];
    s.newer = -1;
    s.older = front_;
    (front_ >= 0 ? uses_[static_cast<std::size_t>(front_)].newer : back_) = slot;
    front_ = slot;
  }
  // A hit on a slot behind the front: it has a newer neighbour, and the
  // front exists, so only its older end can be the list's end.
  void to_front(int slot) {
    Use& s = uses_[static_cast<std::size_t>(slot)];
    uses_[static_cast<std::size_t>(s.newer)].older = s.older;
    (s.older >= 0 ? uses_[static_cast<std::size_t>(s.older)].newer : back_) = s.newer;
    s.older = front_;
    s.newer = -1;
    uses_[static_cast<std::size_t>(front_)].newer = slot;
    front_ = slot;
  }

  std::size_t page_size_;
  std::uint32_t capacity_;
  std::size_t own_count_;
  std::unique_ptr<std::byte[]> own_;  // own_count_ pages end to end
  std::vector<std::int32_t> entry_;
  std::vector<Slot> slots_;
  std::vector<Use> uses_;  // by slot, as slots_
  int front_ = -1;  // most recently used slot; -1: none
  int back_ = -1;   // least recently used
  std::uint64_t evictions_ = 0;
  struct PendingFetch {
    std::uint32_t page = 0;
    std::vector<int> waiters;  // workers woken when it ends
  };
  PendingFetch* pending(std::uint32_t page);
  std::vector<PendingFetch> pending_;  // fetches begun and not ended, in no order
};

}  // namespace nodes
