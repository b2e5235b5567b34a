// Own pages, page placement and the LRU page cache of one processor, driven
// directly (no fibers): placement covers every page once, own pages given
// at once or placed one by one, LRU order, slots in use kept from eviction,
// and miss coalescing bookkeeping.
#include "nodes/machine/node_memory.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <list>
#include <random>
#include <set>
#include <vector>

namespace {

using nodes::Distribution;
using nodes::NodeMemory;
using nodes::PagePlacement;

constexpr std::size_t page_size = 256;

std::vector<std::byte> page_bytes(std::uint32_t page) {
  return std::vector<std::byte>(page_size, static_cast<std::byte>(page & 0xff));
}

std::vector<std::vector<std::byte>> own_pages(const PagePlacement& placement, int node) {
  std::vector<std::vector<std::byte>> pages;
  for (std::uint32_t i = 0; i < placement.own_count(node); ++i) pages.push_back(page_bytes(placement.page_of(node, i)));
  return pages;
}

TEST(PagePlacement, EveryPageHasExactlyOneOwnerAndRoundTrips) {
  for (auto distribution : {Distribution::modulo, Distribution::block}) {
    for (int nodes : {1, 3, 7, 16, 64}) {
      for (std::uint32_t pages : {1u, 5u, 64u, 1000u}) {
        const PagePlacement placement(distribution, nodes, pages);
        std::uint32_t total = 0;
        std::set<std::uint32_t> seen;
        for (int n = 0; n < nodes; ++n) {
          total += placement.own_count(n);
          for (std::uint32_t i = 0; i < placement.own_count(n); ++i) {
            const auto p = placement.page_of(n, i);
            ASSERT_EQ(placement.owner(p), n);
            ASSERT_EQ(placement.own_index(p), i);
            seen.insert(p);
          }
        }
        ASSERT_EQ(total, pages);
        ASSERT_EQ(seen.size(), pages);
      }
    }
  }
}

// Own pages placed one by one, in any order (the host places a database's
// pages in page order across every node), give the memory that own pages
// handed over at once give: the same bytes where each page's entry says.
TEST(NodeMemory, OwnPagesPlacedOneByOneAreTheOwnPagesGivenAtOnce) {
  for (auto distribution : {Distribution::modulo, Distribution::block}) {
    const PagePlacement placement(distribution, 5, 47);
    std::vector<NodeMemory> given, placed;
    for (int n = 0; n < placement.nodes(); ++n) {
      given.emplace_back(placement, n, page_size, own_pages(placement, n), 4);
      placed.emplace_back(placement, n, page_size, 4);
    }
    std::vector<std::uint32_t> order(placement.page_count());
    for (std::uint32_t p = 0; p < order.size(); ++p) order[p] = p;
    std::shuffle(order.begin(), order.end(), std::mt19937(3));
    for (const std::uint32_t p : order)
      placed[static_cast<std::size_t>(placement.owner(p))].place_own(placement.own_index(p), page_bytes(p));
    for (int n = 0; n < placement.nodes(); ++n)
      for (std::uint32_t p = 0; p < placement.page_count(); ++p) {
        const auto& a = given[static_cast<std::size_t>(n)];
        const auto& b = placed[static_cast<std::size_t>(n)];
        ASSERT_EQ(b.entry(p), a.entry(p)) << "node " << n << ", page " << p;
        if (b.entry(p) < 0) continue;
        EXPECT_EQ(b.entry(p) >= 0, placement.owner(p) == n);
        EXPECT_TRUE(std::equal(b.own_page(b.entry(p)), b.own_page(b.entry(p)) + page_size, page_bytes(p).begin()))
            << "node " << n << ", page " << p;
      }
  }
  const PagePlacement placement(Distribution::modulo, 2, 4);
  NodeMemory memory(placement, 0, page_size, 1);
  EXPECT_THROW(memory.place_own(2, page_bytes(4)), std::logic_error);  // node 0 owns two pages
  EXPECT_THROW(memory.place_own(0, std::vector<std::byte>(page_size + 1)), std::logic_error);
}

TEST(PagePlacement, BlockGivesContiguousRanges) {
  const PagePlacement placement(Distribution::block, 4, 10);
  EXPECT_EQ(placement.owner(0), 0);
  EXPECT_EQ(placement.owner(9), 3);
  for (std::uint32_t p = 1; p < 10; ++p) EXPECT_GE(placement.owner(p), placement.owner(p - 1));
}

TEST(NodeMemory, OwnPagesAreFoundByEntry) {
  const PagePlacement placement(Distribution::modulo, 4, 20);
  NodeMemory memory(placement, 1, page_size, own_pages(placement, 1), 2);
  for (std::uint32_t p = 0; p < 20; ++p) {
    const auto e = memory.entry(p);
    if (p % 4 == 1) {
      ASSERT_GE(e, 0);
      EXPECT_EQ(memory.own_page(e)[0], static_cast<std::byte>(p));
    } else {
      EXPECT_EQ(e, -1);
    }
  }
  EXPECT_EQ(memory.own_bytes(), 5 * page_size);
  EXPECT_EQ(memory.resident_bytes(), 5 * page_size);
}

TEST(NodeMemory, EvictsLeastRecentlyUsed) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 2);
  const int a = memory.install(1, page_bytes(1));
  memory.install(3, page_bytes(3));
  EXPECT_EQ(memory.use(a)[0], std::byte{1});  // page 1 is now more recent than page 3
  memory.install(5, page_bytes(5));
  EXPECT_TRUE(NodeMemory::is_slot(memory.entry(1)));
  EXPECT_EQ(memory.entry(3), -1);
  EXPECT_TRUE(NodeMemory::is_slot(memory.entry(5)));
  EXPECT_EQ(memory.slot_bytes(NodeMemory::slot_of_entry(memory.entry(5)))[0], std::byte{5});
  EXPECT_EQ(memory.evictions(), 1u);
}

TEST(NodeMemory, SlotInUseIsNeverEvicted) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 2);
  const int old_slot = memory.install(1, page_bytes(1));
  memory.install(3, page_bytes(3));
  const std::vector<int> in_use{old_slot};  // page 1 is least recently used but in use
  memory.install(5, page_bytes(5), in_use);
  memory.install(7, page_bytes(7), in_use);
  EXPECT_TRUE(NodeMemory::is_slot(memory.entry(1)));
  EXPECT_EQ(memory.slot_bytes(old_slot)[0], std::byte{1});
  memory.install(9, page_bytes(9));
  EXPECT_EQ(memory.entry(1), -1);
}

// A page held by reference is the owner's bytes themselves, not a copy;
// the slot it leaves, taken by a copy, gets a buffer of its own, and the
// owner's page is never written.
TEST(NodeMemory, APageHeldByReferenceIsTheOwnersAndItsSlotCopiesLater) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 1);
  const std::vector<std::byte> owners = page_bytes(1);
  const int slot = memory.install(1, owners, {}, NodeMemory::Holding::reference);
  EXPECT_EQ(memory.use(slot), owners.data());
  EXPECT_EQ(memory.install(3, page_bytes(3)), slot);  // evicts page 1
  EXPECT_EQ(memory.entry(1), -1);
  EXPECT_NE(memory.slot_bytes(slot), owners.data());
  EXPECT_EQ(memory.slot_bytes(slot)[0], std::byte{3});
  EXPECT_EQ(owners, page_bytes(1));
  EXPECT_EQ(memory.install(5, page_bytes(5)), slot);  // the buffer, reused, takes the copy
  EXPECT_EQ(memory.slot_bytes(slot)[page_size - 1], std::byte{5});
  EXPECT_EQ(memory.resident_bytes(), memory.own_bytes() + page_size);
}

// A long random run of installs and uses, with slots taken in and out of use,
// against a plain list kept in recency order: the cache must hold exactly
// the pages the list says.
TEST(NodeMemory, MatchesAListKeptInRecencyOrder) {
  constexpr std::uint32_t pages = 200, capacity = 7;
  const PagePlacement placement(Distribution::modulo, 2, pages);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), capacity);
  std::list<std::uint32_t> recency;  // cached pages, most recent first
  std::vector<int> in_use;
  std::mt19937 random(5);
  for (int step = 0; step < 20000; ++step) {
    const std::uint32_t page = 2 * (random() % (pages / 2)) + 1;  // node 1's pages
    const std::int32_t entry = memory.entry(page);
    if (NodeMemory::is_slot(entry)) {
      const int slot = NodeMemory::slot_of_entry(entry);
      ASSERT_EQ(memory.use(slot)[0], static_cast<std::byte>(page));
      recency.remove(page);
      recency.push_front(page);
      if (random() % 4 == 0) {  // into or out of use, keeping one slot free to evict
        const auto it = std::find(in_use.begin(), in_use.end(), slot);
        if (it != in_use.end()) in_use.erase(it);
        else if (in_use.size() + 1 < capacity) in_use.push_back(slot);
      }
      continue;
    }
    ASSERT_EQ(entry, -1);
    if (recency.size() == capacity) {
      auto victim = recency.end();
      do --victim;
      while (std::count(in_use.begin(), in_use.end(), NodeMemory::slot_of_entry(memory.entry(*victim))) > 0);
      recency.erase(victim);
    }
    memory.install(page, page_bytes(page), in_use);
    recency.push_front(page);
    for (std::uint32_t p = 1; p < pages; p += 2)
      ASSERT_EQ(NodeMemory::is_slot(memory.entry(p)), std::find(recency.begin(), recency.end(), p) != recency.end())
          << "page " << p << " after step " << step;
  }
  EXPECT_GT(memory.evictions(), 1000u);
}

TEST(NodeMemory, AllSlotsInUseIsAnError) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 1);
  const std::vector<int> in_use{memory.install(1, page_bytes(1))};
  EXPECT_THROW(memory.install(3, page_bytes(3), in_use), std::logic_error);
}

TEST(NodeMemory, ResidentBytesNeverExceedOwnShareAndCache) {
  const PagePlacement placement(Distribution::modulo, 4, 64);
  NodeMemory memory(placement, 2, page_size, own_pages(placement, 2), 5);
  const std::size_t bound = memory.own_bytes() + 5 * page_size;
  for (std::uint32_t round = 0; round < 3; ++round)
    for (std::uint32_t p = 0; p < 64; ++p)
      if (memory.entry(p) == -1) {
        memory.install(p, page_bytes(p));
        ASSERT_LE(memory.resident_bytes(), bound);
      }
  EXPECT_EQ(memory.resident_bytes(), bound);
}

TEST(NodeMemory, CacheCapacityIsCappedAtRemotePages) {
  const PagePlacement placement(Distribution::modulo, 4, 8);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 1000);
  EXPECT_EQ(memory.cache_capacity(), 6u);
  const PagePlacement single(Distribution::modulo, 1, 8);
  EXPECT_EQ(NodeMemory(single, 0, page_size, own_pages(single, 0), 4).cache_capacity(), 0u);
}

TEST(NodeMemory, SecondMissOnAPendingPageWaitsForTheFirst) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 2);
  EXPECT_TRUE(memory.begin_fetch(7));
  EXPECT_FALSE(memory.begin_fetch(7));
  memory.add_waiter(7, 1);
  memory.add_waiter(7, 2);
  EXPECT_EQ(memory.end_fetch(7), (std::vector<int>{1, 2}));
  EXPECT_TRUE(memory.begin_fetch(7));
}

// Several fetches pending at once (one per worker), ended in any order:
// each keeps its own waiters, and a fetch never begun cannot end.
TEST(NodeMemory, PendingFetchesKeepTheirOwnWaitersWhateverOrderTheyEnd) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 2);
  for (std::uint32_t page : {1u, 3u, 5u}) EXPECT_TRUE(memory.begin_fetch(page));
  memory.add_waiter(3, 4);
  memory.add_waiter(1, 2);
  memory.add_waiter(5, 6);
  memory.add_waiter(3, 5);
  EXPECT_EQ(memory.end_fetch(1), (std::vector<int>{2}));
  EXPECT_FALSE(memory.begin_fetch(5));
  EXPECT_EQ(memory.end_fetch(5), (std::vector<int>{6}));
  EXPECT_TRUE(memory.begin_fetch(1));
  EXPECT_EQ(memory.end_fetch(3), (std::vector<int>{4, 5}));
  EXPECT_EQ(memory.end_fetch(1), std::vector<int>{});
  EXPECT_THROW(memory.end_fetch(3), std::logic_error);
  EXPECT_THROW(memory.add_waiter(9, 1), std::logic_error);
}

TEST(NodeMemory, WrongSizedPageIsRejected) {
  const PagePlacement placement(Distribution::modulo, 2, 10);
  NodeMemory memory(placement, 0, page_size, own_pages(placement, 0), 2);
  EXPECT_THROW(memory.install(1, std::vector<std::byte>(10)), std::runtime_error);
}

}  // namespace
