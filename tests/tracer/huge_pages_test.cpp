// HugePageAllocator and advise_huge_pages: a large block is 2 MiB-aligned
// and its mapping carries the kernel's huge-page advice (the "hg" flag in
// /proc/self/smaps), a small one is ordinary, contents survive growth across
// the threshold, advising a range marks only the whole 2 MiB pages in it, and
// a vector truncated gives back the whole pages past the elements it keeps.
#include "tracer/huge_pages.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace tracer {
namespace {

// The VmFlags of the mapping holding `address`, or "" if none is listed.
std::string vm_flags_of(const void* address) {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      inside = lo <= a && a < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

// Whether this kernel takes huge-page advice at all: it may have no
// transparent huge pages, or refuse them to this process (prctl).
bool kernel_takes_advice() {
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled")) return false;
  void* probe = ::mmap(nullptr, 2 * kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (probe == MAP_FAILED) return false;
  const bool taken = ::madvise(probe, 2 * kHugePage, MADV_HUGEPAGE) == 0;
  ::munmap(probe, 2 * kHugePage);
  return taken;
}

TEST(HugePages, ALargeBlockIsAlignedAndAdvised) {
  if (!kernel_takes_advice()) GTEST_SKIP() << "this kernel takes no huge-page advice";
  BigVector<std::uint64_t> v(3 * kHugePage / sizeof(std::uint64_t));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHugePage, 0u);
  const std::string flags = vm_flags_of(v.data() + v.size() / 2);
  ASSERT_FALSE(flags.empty()) << "no mapping listed for the block";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
}

TEST(HugePages, ContentsSurviveGrowthAcrossTheThreshold) {
  BigVector<std::uint32_t> v;
  const std::size_t n = 2 * kHugePage / sizeof(std::uint32_t) + 12345;
  for (std::uint32_t i = 0; i < n; ++i) v.push_back(i * 2654435761u);
  ASSERT_EQ(v.size(), n);
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(v[i], i * 2654435761u) << i;
  BigVector<std::uint32_t> copy = v;  // a second large block, freed with the first
  EXPECT_EQ(copy, v);
  v.clear();
  v.shrink_to_fit();  // a large block handed back, then a small one taken
  v.assign(10, 7u);
  EXPECT_EQ(v, BigVector<std::uint32_t>(10, 7u));
}

TEST(HugePages, AdvisingARangeMarksOnlyItsWholeHugePages) {
  if (!kernel_takes_advice()) GTEST_SKIP() << "this kernel takes no huge-page advice";
  const std::size_t bytes = 4 * kHugePage;
  void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(map, MAP_FAILED);
  const auto base = (reinterpret_cast<std::uintptr_t>(map) + kHugePage - 1) & ~(kHugePage - 1);
  auto* p = reinterpret_cast<std::byte*>(base);  // 2 MiB-aligned, with at least 2 MiB after it
  // From 1 KiB into the first huge page to 1 KiB into the second: no whole
  // huge page inside, nothing advised.
  advise_huge_pages(p + 1024, kHugePage);
  EXPECT_EQ(vm_flags_of(p + 1024).find(" hg"), std::string::npos);
  // From the start of the first to 1 KiB into the second: the first only.
  advise_huge_pages(p, kHugePage + 1024);
  EXPECT_NE(vm_flags_of(p).find(" hg"), std::string::npos);
  EXPECT_EQ(vm_flags_of(p + kHugePage).find(" hg"), std::string::npos);
  ::munmap(map, bytes);
}

TEST(HugePages, TruncatingGivesBackTheWholePagesPastTheElementsKept) {
  constexpr std::size_t page = 4096;
  BigVector<std::uint32_t> v(3 * kHugePage / sizeof(std::uint32_t));  // every page written
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint32_t>(i * 2654435761u);
  const std::uint32_t* data = v.data();
  const std::size_t capacity = v.capacity();
  const std::size_t keep = 1500;  // 6000 bytes: the first page and part of the second
  truncate_and_give_back(v, keep);
  ASSERT_EQ(v.size(), keep);
  EXPECT_EQ(v.data(), data);  // the storage stays the vector's
  EXPECT_EQ(v.capacity(), capacity);
  for (std::size_t i = 0; i < keep; ++i) ASSERT_EQ(v[i], static_cast<std::uint32_t>(i * 2654435761u)) << i;
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(data) % page, 0u);
  const std::size_t pages = capacity * sizeof(std::uint32_t) / page;
  std::vector<unsigned char> resident(pages);
  ASSERT_EQ(::mincore(const_cast<std::uint32_t*>(data), pages * page, resident.data()), 0);
  EXPECT_TRUE(resident[0] & 1);
  EXPECT_TRUE(resident[1] & 1);  // holds the last elements kept
  std::size_t still_resident = 0;
  for (std::size_t p = 2; p < pages; ++p) still_resident += resident[p] & 1;
  EXPECT_EQ(still_resident, 0u) << "of " << pages - 2 << " pages past the elements";
  v.resize(capacity);  // grown back into storage that was given back
  EXPECT_EQ(v[keep], 0u);
  EXPECT_EQ(v[capacity - 1], 0u);
}

}  // namespace
}  // namespace tracer
