// The shared virtual memory of one processor: a tracer::PageSource per
// pixel-computer fiber over the node's NodeMemory (own pages + LRU cache).
//
// An access is answered from the node's own pages, else from the cache, else
// by a page request to the owner's page server: only the requesting fiber
// blocks (inside PageFetch, on the network) until the page arrives and is
// installed in the cache, evicting the least recently used unpinned page.
// A second worker missing on a page already being fetched sends no request:
// it waits on its own wake channel (capacity 1) for the fetcher to install
// it. Pages are read-only during rendering: no coherence protocol. A
// worker's pin is the cache slot it last returned, so no install evicts
// bytes still in use; it drops the pin before it blocks. A node's fibers
// share one OS thread, so nothing here is locked. The protocol, step by
// step: docs/architecture.md, "The path of one page request".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/machine/node_memory.hpp"
#include "nodes/net/packet.hpp"
#include "tracer/database.hpp"

namespace nodes {

// Blocks the calling fiber until the owner's page_reply for `page` arrives,
// and returns it (its bytes: page_reply_bytes, messages.hpp).
using PageFetch = std::function<Packet(std::uint32_t page)>;

// Every access ends in exactly one of the four counts.
struct SvmStats {
  std::uint64_t own_hits = 0;
  std::uint64_t cache_hits = 0;
  std::uint64_t misses = 0;     // page requests sent (page communications)
  std::uint64_t coalesced = 0;  // misses served by another worker's pending request

  std::uint64_t accesses() const { return own_hits + cache_hits + misses + coalesced; }
  SvmStats& operator+=(const SvmStats& o);
  // Accesses not answered by own pages or the cache, over all accesses.
  double miss_ratio() const;
};

class NodeSvm;

class SvmSource final : public tracer::PageSource {
 public:
  SvmSource(NodeSvm& node, int worker, PageFetch fetch);

  const std::byte* page(tracer::PageId id) override;
  void release() { pinned_ = -1; }  // drop the pin: call before blocking outside page()
  const SvmStats& stats() const { return stats_; }

 private:
  friend class NodeSvm;
  const std::byte* miss(tracer::PageId id);
  const std::byte* from_slot(int slot) {
    pinned_ = slot;
    return memory_.use(slot);
  }
  const std::byte* fetch_and_install(tracer::PageId id);

  NodeSvm& node_;
  NodeMemory& memory_;
  int worker_;
  PageFetch fetch_;
  int pinned_ = -1;  // slot this source last returned, or -1
  csp::Channel<int> wake_;
  SvmStats stats_;
};

// A processor's memory and its workers' page sources.
class NodeSvm {
 public:
  explicit NodeSvm(NodeMemory memory) : memory_(std::move(memory)) {}
  NodeSvm(const NodeSvm&) = delete;
  NodeSvm& operator=(const NodeSvm&) = delete;

  SvmSource& add_worker(PageFetch fetch);  // worker ids are 0, 1, ... in order
  SvmSource& worker(int w) { return *workers_[static_cast<std::size_t>(w)]; }
  int worker_count() const { return static_cast<int>(workers_.size()); }

  NodeMemory& memory() { return memory_; }
  const NodeMemory& memory() const { return memory_; }
  SvmStats stats() const;  // summed over the workers

 private:
  friend class SvmSource;
  // Installs a fetched page where no worker's pin is.
  int install(std::uint32_t page, std::span<const std::byte> bytes, NodeMemory::Holding holding);

  NodeMemory memory_;
  std::vector<std::unique_ptr<SvmSource>> workers_;
};

}  // namespace nodes
