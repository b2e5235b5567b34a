// Page sources of the shared virtual memory (see svm.hpp).
#include "nodes/machine/svm.hpp"

#include <string>

#include "nodes/machine/messages.hpp"

namespace nodes {

SvmStats& SvmStats::operator+=(const SvmStats& o) {
  own_hits += o.own_hits;
  cache_hits += o.cache_hits;
  misses += o.misses;
  coalesced += o.coalesced;
  return *this;
}

double SvmStats::miss_ratio() const {
  const std::uint64_t all = accesses();
  return all == 0 ? 0.0 : static_cast<double>(misses + coalesced) / static_cast<double>(all);
}

SvmSource::SvmSource(NodeSvm& node, int worker, PageFetch fetch)
    : node_(node),
      memory_(node.memory_),
      worker_(worker),
      fetch_(std::move(fetch)),
      wake_("svm wake " + std::to_string(worker), 1) {}

const std::byte* SvmSource::page(tracer::PageId id) {
  const std::int32_t entry = memory_.entry(id);
  if (entry >= 0) {
    ++stats_.own_hits;
    release();
    return memory_.own_page(entry);
  }
  if (NodeMemory::is_slot(entry)) {
    ++stats_.cache_hits;
    return from_slot(NodeMemory::slot_of_entry(entry));
  }
  return miss(id);
}

const std::byte* SvmSource::miss(tracer::PageId id) {
  release();
  // page() found no entry, so the first pass cannot hit the cache.
  for (;;) {
    const std::int32_t entry = memory_.entry(id);
    if (NodeMemory::is_slot(entry)) {
      ++stats_.coalesced;
      return from_slot(NodeMemory::slot_of_entry(entry));
    }
    if (memory_.begin_fetch(id)) {
      ++stats_.misses;
      return fetch_and_install(id);
    }
    memory_.add_waiter(id, worker_);
    wake_.reader().read();
  }
}

const std::byte* SvmSource::fetch_and_install(tracer::PageId id) {
  const auto reply = fetch_(id);
  if (page_reply_id(reply) != id)
    throw std::logic_error("asked for page " + std::to_string(id) + ", got page " +
                           std::to_string(page_reply_id(reply)));
  // Pin before waking anyone, so the page stays until this worker moves on.
  // A reply that carries the owner's page by reference (inside one process)
  // is held so: the page never changes while the machine runs.
  const auto holding = reply.shared.empty() ? NodeMemory::Holding::copy : NodeMemory::Holding::reference;
  const std::byte* bytes = from_slot(node_.install(id, page_reply_bytes(reply), holding));
  for (int waiter : memory_.end_fetch(id)) node_.worker(waiter).wake_.writer().write(1);
  return bytes;
}

SvmSource& NodeSvm::add_worker(PageFetch fetch) {
  workers_.push_back(std::make_unique<SvmSource>(*this, worker_count(), std::move(fetch)));
  return *workers_.back();
}

int NodeSvm::install(std::uint32_t page, std::span<const std::byte> bytes, NodeMemory::Holding holding) {
  std::vector<int> pinned;  // empty, and so never allocated, unless a worker holds a pin
  for (const auto& w : workers_)
    if (w->pinned_ >= 0) pinned.push_back(w->pinned_);
  return memory_.install(page, bytes, pinned, holding);
}

SvmStats NodeSvm::stats() const {
  SvmStats total;
  for (const auto& w : workers_) total += w->stats();
  return total;
}

}  // namespace nodes
