// HugePageAllocator: the allocator of the database build's large arrays.
// A block of at least kHugePage bytes is taken 2 MiB-aligned and advised
// for transparent huge pages (madvise MADV_HUGEPAGE), so that where the
// kernel gives huge pages only on request (THP "madvise" mode) filling it
// costs a page fault per 2 MiB instead of one per 4 KiB: building Tetra10
// touches some 300 MB of fresh memory. The advice is a hint: where huge
// pages are off, or the call fails, the block is ordinary memory. Smaller
// blocks come from std::allocator. Stateless: any two compare equal.
// truncate_and_give_back lets a vector consumed from its back shrink, and
// return_freed_heap gives what a step freed back to the system.
#pragma once

#include <sys/mman.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace tracer {

inline constexpr std::size_t kHugePage = std::size_t{2} << 20;

// Advises the whole 2 MiB pages inside [data, data + bytes) for huge pages,
// for storage not yet written (a fresh block, or reserved capacity).
inline void advise_huge_pages(const void* data, std::size_t bytes) {
  const auto first = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (first + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t end = (first + bytes) & ~(kHugePage - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // a hint
}

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage) return std::allocator<T>().allocate(n);
    void* p = ::operator new(bytes, std::align_val_t{kHugePage});
    advise_huge_pages(p, bytes);  // a hint; failure leaves ordinary pages
    return static_cast<T*>(p);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePage)
      std::allocator<T>().deallocate(p, n);
    else
      ::operator delete(p, std::align_val_t{kHugePage});
  }

  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A vector whose large storage is advised for huge pages.
template <class T>
using BigVector = std::vector<T, HugePageAllocator<T>>;

// Gives the heap's free memory back to the system (glibc's malloc_trim),
// not only to its free lists: a big step's arrays are mapped afresh and
// would not reuse what an earlier one freed, so it would count in the peak.
inline void return_freed_heap() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

// Destroys the elements of v from `count` on, and gives the whole pages of
// storage past the elements left back to the system (madvise MADV_DONTNEED):
// they hold no object, and read as zeros if the vector grows into them again.
// So a vector consumed from its back shrinks in memory as it goes.
template <class T>
void truncate_and_give_back(BigVector<T>& v, std::size_t count) {
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(std::min(count, v.size())), v.end());
  constexpr std::uintptr_t page = 4096;  // the smallest page: a larger one is whole pages of it
  const auto used = reinterpret_cast<std::uintptr_t>(v.data() + v.size());
  const auto end = reinterpret_cast<std::uintptr_t>(v.data() + v.capacity()) & ~(page - 1);
  const std::uintptr_t begin = (used + page - 1) & ~(page - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_DONTNEED);
}

}  // namespace tracer
