// Own pages and LRU cache of one processor (see node_memory.hpp).
#include "nodes/machine/node_memory.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace nodes {

PagePlacement::PagePlacement(Distribution distribution, int nodes, std::uint32_t page_count)
    : distribution_(distribution), nodes_(nodes), page_count_(page_count) {
  if (nodes < 1) throw std::invalid_argument("page placement needs at least one node");
}

std::uint32_t PagePlacement::block_first(int node) const {
  return static_cast<std::uint32_t>(std::uint64_t{page_count_} * static_cast<std::uint64_t>(node) /
                                    static_cast<std::uint64_t>(nodes_));
}

int PagePlacement::owner(std::uint32_t page) const {
  if (distribution_ == Distribution::modulo) return static_cast<int>(page % static_cast<std::uint32_t>(nodes_));
  // The guess is within one of the owner because block_first is a floor.
  int n = static_cast<int>(std::uint64_t{page} * static_cast<std::uint64_t>(nodes_) / page_count_);
  while (n + 1 < nodes_ && block_first(n + 1) <= page) ++n;
  while (n > 0 && block_first(n) > page) --n;
  return n;
}

std::uint32_t PagePlacement::own_index(std::uint32_t page) const {
  if (distribution_ == Distribution::modulo) return page / static_cast<std::uint32_t>(nodes_);
  return page - block_first(owner(page));
}

std::uint32_t PagePlacement::page_of(int node, std::uint32_t index) const {
  if (distribution_ == Distribution::modulo)
    return index * static_cast<std::uint32_t>(nodes_) + static_cast<std::uint32_t>(node);
  return block_first(node) + index;
}

std::uint32_t PagePlacement::own_count(int node) const {
  if (distribution_ == Distribution::block) return block_first(node + 1) - block_first(node);
  const auto n = static_cast<std::uint32_t>(nodes_);
  const auto k = static_cast<std::uint32_t>(node);
  return page_count_ / n + (k < page_count_ % n ? 1 : 0);
}

NodeMemory::NodeMemory(const PagePlacement& placement, int node, std::size_t page_size,
                       std::vector<std::vector<std::byte>> own_pages, std::uint32_t cache_pages)
    : NodeMemory(placement, node, page_size, cache_pages) {
  if (own_pages.size() != own_count_)
    throw std::logic_error("node " + std::to_string(node) + " given the wrong number of own pages");
  for (std::size_t i = 0; i < own_count_; ++i) {
    place_own(static_cast<std::uint32_t>(i), own_pages[i]);
    std::vector<std::byte>().swap(own_pages[i]);
  }
}

NodeMemory::NodeMemory(const PagePlacement& placement, int node, std::size_t page_size, std::uint32_t cache_pages)
    : page_size_(page_size),
      own_count_(placement.own_count(node)),
      own_(std::make_unique_for_overwrite<std::byte[]>(own_count_ * page_size)),
      entry_(placement.page_count(), -1) {
  for (std::uint32_t i = 0; i < own_count_; ++i) entry_[placement.page_of(node, i)] = static_cast<std::int32_t>(i);
  // More slots than remote pages could never be filled.
  capacity_ = std::min(cache_pages, placement.page_count() - static_cast<std::uint32_t>(own_count_));
  slots_.reserve(capacity_);
  uses_.reserve(capacity_);
}

void NodeMemory::place_own(std::uint32_t index, std::span<const std::byte> bytes) {
  if (index >= own_count_) throw std::logic_error("own page " + std::to_string(index) + " out of range");
  if (bytes.size() != page_size_) throw std::logic_error("own page of the wrong size");
  std::memcpy(own_.get() + std::size_t{index} * page_size_, bytes.data(), page_size_);
}

int NodeMemory::take_slot(std::span<const int> in_use) {
  if (slots_.size() < capacity_) {
    slots_.emplace_back();
    uses_.emplace_back();
    const int slot = static_cast<int>(slots_.size() - 1);
    push_front(slot);
    return slot;
  }
  int victim = back_;
  while (victim >= 0 && std::find(in_use.begin(), in_use.end(), victim) != in_use.end())
    victim = uses_[static_cast<std::size_t>(victim)].newer;
  if (victim < 0) throw std::logic_error("page cache: every slot is in use");
  entry_[slots_[static_cast<std::size_t>(victim)].page] = -1;
  ++evictions_;
  return victim;
}

int NodeMemory::install(std::uint32_t page, std::span<const std::byte> bytes, std::span<const int> in_use,
                        Holding holding) {
  if (bytes.size() != page_size_) throw std::runtime_error("page " + std::to_string(page) + " arrived with a wrong size");
  if (entry_[page] != -1) throw std::logic_error("page " + std::to_string(page) + " installed twice");
  if (capacity_ == 0) throw std::logic_error("page cache has no slot for remote page " + std::to_string(page));
  const int slot = take_slot(in_use);
  Slot& s = slots_[static_cast<std::size_t>(slot)];
  if (holding == Holding::reference) {
    uses_[static_cast<std::size_t>(slot)].data = bytes.data();
  } else {
    if (!s.bytes) s.bytes = std::make_unique<std::byte[]>(page_size_);
    std::memcpy(s.bytes.get(), bytes.data(), page_size_);
    uses_[static_cast<std::size_t>(slot)].data = s.bytes.get();
  }
  s.page = page;
  entry_[page] = -2 - slot;
  use(slot);
  return slot;
}

// The pending fetches are few (one per worker of the node at most), so a
// short list searched in order, whose entries are reused, serves them with
// no allocation per miss.
NodeMemory::PendingFetch* NodeMemory::pending(std::uint32_t page) {
  for (PendingFetch& p : pending_)
    if (p.page == page) return &p;
  return nullptr;
}

bool NodeMemory::begin_fetch(std::uint32_t page) {
  if (pending(page)) return false;
  pending_.push_back({page, {}});
  return true;
}

void NodeMemory::add_waiter(std::uint32_t page, int worker) {
  PendingFetch* p = pending(page);
  if (!p) throw std::logic_error("a waiter for a page fetch that never began");
  p->waiters.push_back(worker);
}

std::vector<int> NodeMemory::end_fetch(std::uint32_t page) {
  PendingFetch* p = pending(page);
  if (!p) throw std::logic_error("end of a page fetch that never began");
  std::vector<int> waiters = std::move(p->waiters);
  *p = std::move(pending_.back());
  pending_.pop_back();
  return waiters;
}

}  // namespace nodes
