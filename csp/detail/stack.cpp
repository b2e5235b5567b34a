// Process stacks with guard pages (see stack.hpp).
#include "csp/detail/stack.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <fstream>
#include <mutex>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

namespace csp::detail {
namespace {

std::atomic<std::size_t> guarded{0};

// Guarded stacks freed, kept for the next process of their size: unmapping
// one while other threads of the program run interrupts each of their
// processors to flush its address translations, and a new mapping has its
// pages faulted in again. At most guarded_limit() stacks, by the count
// above, which includes these. The store itself is never freed, since a
// stack may be freed while the program exits.
struct Spares {
  std::mutex mutex;
  std::unordered_map<std::size_t, std::vector<boost::context::stack_context>> by_size;  // guarded by mutex
};
Spares& spares() {
  static Spares* const kept = new Spares;
  return *kept;
}

std::size_t read_guarded_limit() {
  std::size_t max_map_count = 65530;
  std::ifstream in("/proc/sys/vm/max_map_count");
  in >> max_map_count;
  return max_map_count / 4;
}

void* map(std::size_t bytes) {
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
  return p == MAP_FAILED ? nullptr : p;
}

}  // namespace

bool address_space_free(std::size_t bytes) {
  void* p = ::mmap(nullptr, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (p == MAP_FAILED) return false;
  ::munmap(p, bytes);
  return true;
}

ProcessStack::ProcessStack(std::size_t size) : page_(static_cast<std::size_t>(::sysconf(_SC_PAGESIZE))) {
  size_ = (size + page_ - 1) / page_ * page_;
}

std::size_t ProcessStack::guarded_alive() { return guarded.load(std::memory_order_relaxed); }

std::size_t ProcessStack::guarded_limit() {
  static const std::size_t limit = read_guarded_limit();
  return limit;
}

boost::context::stack_context ProcessStack::allocate() {
  {
    Spares& s = spares();
    std::lock_guard<std::mutex> lk(s.mutex);
    const auto kept = s.by_size.find(size_ + page_);
    if (kept != s.by_size.end() && !kept->second.empty()) {
      const boost::context::stack_context sctx = kept->second.back();
      kept->second.pop_back();
      return sctx;
    }
  }
  boost::context::stack_context sctx;
  if (guarded.fetch_add(1, std::memory_order_relaxed) < guarded_limit()) {
    if (void* p = map(size_ + page_)) {
      if (::mprotect(p, page_, PROT_NONE) == 0) {
        sctx.size = size_ + page_;
        sctx.sp = static_cast<char*>(p) + sctx.size;
        return sctx;
      }
      ::munmap(p, size_ + page_);
    }
  }
  guarded.fetch_sub(1, std::memory_order_relaxed);
  void* p = map(size_);
  if (!p)
    throw std::system_error(errno, std::generic_category(),
                            "no memory for a " + std::to_string(size_ / 1024) + " KB process stack");
  sctx.size = size_;
  sctx.sp = static_cast<char*>(p) + sctx.size;
  return sctx;
}

void ProcessStack::deallocate(boost::context::stack_context& sctx) noexcept {
  if (sctx.size != size_) {
    try {
      Spares& s = spares();
      std::lock_guard<std::mutex> lk(s.mutex);
      s.by_size[sctx.size].push_back(sctx);
      return;
    } catch (...) {  // no room to keep it: unmap it after all
    }
    guarded.fetch_sub(1, std::memory_order_relaxed);
  }
  ::munmap(static_cast<char*>(sctx.sp) - sctx.size, sctx.size);
}

}  // namespace csp::detail
