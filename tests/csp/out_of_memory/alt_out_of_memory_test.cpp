// What an ALT leaves behind when memory runs out while a guard is added.
// This executable replaces the global operator new so that a test can make
// every allocation of its own thread fail for a while (FailingAllocations);
// it is a program of its own so that no other test runs with that
// replacement.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>
#include <stdexcept>

#include "csp/csp.hpp"

namespace {

thread_local bool allocations_fail = false;

// While one lives, every allocation on this thread throws std::bad_alloc.
class FailingAllocations {
 public:
  FailingAllocations() { allocations_fail = true; }
  ~FailingAllocations() { allocations_fail = false; }
  FailingAllocations(const FailingAllocations&) = delete;
  FailingAllocations& operator=(const FailingAllocations&) = delete;
};

}  // namespace

void* operator new(std::size_t size) {
  if (allocations_fail) throw std::bad_alloc();
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
// GCC sees these replacements pair malloc with operator delete once it
// inlines them, and warns of a mismatch that is the point of replacing both.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace {

// The guard list of an ALT with one guard is full, so a second guard must
// grow it. When that fails, the second channel must not be left ringing the
// ALT's bell: once the ALT is gone the bell is freed, and a channel still
// ringing it would write to freed memory (a render that ran out of memory
// hung so, a router spinning on the lock of a bell long gone). Another ALT
// may then watch the channel, which it refuses while a bell is registered.
TEST(AltDoorbell, AGuardAddedWithoutMemoryLeavesItsChannelUnwatched) {
  csp::Channel<int> first("first", 1), second("second", 1);
  {
    csp::Alt alt(csp::Alt::Waiting::doorbell);
    alt.add_input(first.reader());
    {
      const FailingAllocations no_memory;
      EXPECT_THROW(alt.add_input(second.reader()), std::bad_alloc);
    }
    EXPECT_EQ(alt.guard_count(), 1u);
    // Memory is back: the same ALT takes the channel it could not.
    EXPECT_EQ(alt.add_input(second.reader()), 1u);
  }
  int v = 7;
  EXPECT_TRUE(second.writer().try_write(v));
  csp::Alt again(csp::Alt::Waiting::doorbell);
  EXPECT_NO_THROW(again.add_input(second.reader()));
}

}  // namespace
