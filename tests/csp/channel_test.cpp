// Channel semantics: rendezvous, ordering, buffering, poison, move-only
// values, ends bound to no channel.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "csp/csp.hpp"

namespace {

using namespace std::chrono_literals;

// Both processes share one thread, so the writer switches nowhere between
// setting `writing` and returning from write() but inside write(): once the
// reader sees `writing`, `written` is still false unless write() returned
// with no reader there.
TEST(Channel, WriterBlocksUntilRead) {
  csp::Channel<int> c("c");
  bool writing = false, written = false;
  int got = 0;
  csp::Runtime rt(1);
  rt.spawn("writer", 0, [out = c.writer(), &writing, &written]() mutable {
    writing = true;
    out.write(7);
    written = true;
  });
  rt.spawn("reader", 0, [in = c.reader(), &writing, &written, &got]() mutable {
    for (int i = 0; i < 100 && !writing; ++i) csp::yield();
    ASSERT_TRUE(writing);
    EXPECT_FALSE(written);
    got = in.read();
  });
  rt.run();
  EXPECT_TRUE(written);
  EXPECT_EQ(got, 7);
}

TEST(Channel, KeepsOrderPerChannel) {
  for (std::size_t capacity : {0u, 1u, 3u}) {
    csp::Channel<int> c("c", capacity);
    std::vector<int> got;
    csp::Runtime rt(1);
    rt.spawn("writer", 0, [out = c.writer()]() mutable {
      for (int i = 0; i < 1000; ++i) out.write(i);
    });
    rt.spawn("reader", 0, [in = c.reader(), &got]() mutable {
      for (int i = 0; i < 1000; ++i) got.push_back(in.read());
    });
    rt.run();
    ASSERT_EQ(got.size(), 1000u);
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(got[i], i) << "capacity " << capacity;
  }
}

TEST(Channel, BufferHoldsExactlyCapacity) {
  for (std::size_t k : {1u, 2u, 5u}) {
    csp::Channel<int> c("c", k);
    std::size_t started = 0, done = 0;  // writes begun, and returned, before the reader reads
    csp::Runtime rt(1);
    rt.spawn("writer", 0, [out = c.writer(), &started, &done, k]() mutable {
      for (std::size_t i = 0; i <= k; ++i) {
        ++started;
        out.write(static_cast<int>(i));
        ++done;
      }
    });
    rt.spawn("reader", 0, [in = c.reader(), &started, &done, k]() mutable {
      // One thread: the writer switches only inside write(), so once it has
      // begun the k+1-th, that write is blocked, or returned when it should not.
      for (int i = 0; i < 100 && started <= k; ++i) csp::yield();
      ASSERT_EQ(started, k + 1);
      EXPECT_EQ(done, k);  // the k+1-th write is still blocked
      for (std::size_t i = 0; i <= k; ++i) EXPECT_EQ(in.read(), static_cast<int>(i));
    });
    rt.run();
    EXPECT_EQ(done, k + 1);
  }
}

// A large buffer grows its storage as values arrive: it still holds exactly
// its capacity, in order, also when growth finds the values wrapped around.
TEST(Channel, LargeBufferHoldsItsCapacityInOrderAsItGrows) {
  constexpr int capacity = 100;
  csp::Channel<int> c("c", capacity);
  auto in = c.reader();
  auto out = c.writer();
  int next_in = 0, next_out = 0;
  for (int v : {0, 1, 2}) {
    int value = v;
    ASSERT_TRUE(out.try_write(value));
  }
  next_in = 3;
  EXPECT_EQ(in.try_read(), next_out++);
  EXPECT_EQ(in.try_read(), next_out++);
  for (int value = next_in; value < next_out + capacity; ++value, ++next_in) ASSERT_TRUE(out.try_write(value));
  int refused = -1;
  EXPECT_FALSE(out.try_write(refused));
  while (next_out < next_in) EXPECT_EQ(in.try_read(), next_out++);
  EXPECT_FALSE(in.try_read().has_value());
}

TEST(Channel, TryOperationsNeverBlock) {
  csp::Channel<int> c("c", 1);
  auto in = c.reader();
  auto out = c.writer();
  EXPECT_FALSE(in.try_read().has_value());
  int v = 4;
  EXPECT_TRUE(out.try_write(v));
  int w = 5;
  EXPECT_FALSE(out.try_write(w));
  EXPECT_EQ(w, 5);
  EXPECT_EQ(in.try_read(), 4);
  csp::Channel<int> rendezvous("r");
  int x = 1;
  EXPECT_FALSE(rendezvous.writer().try_write(x));
}

// try_read_each takes at most `most` values, in order, under one call;
// none from an empty channel; poison throws.
TEST(Channel, TryReadEachTakesAtMostWhatIsAskedInOrder) {
  csp::Channel<std::unique_ptr<int>> c("c", 5);
  auto in = c.reader();
  auto out = c.writer();
  std::vector<int> got;
  const auto take = [&got](std::unique_ptr<int>& v) { got.push_back(*std::exchange(v, nullptr)); };
  EXPECT_EQ(in.try_read_each(3, take), 0u);
  for (int i = 0; i < 5; ++i) {
    auto v = std::make_unique<int>(i);
    ASSERT_TRUE(out.try_write(v));
  }
  EXPECT_EQ(in.try_read_each(3, take), 3u);
  EXPECT_EQ(got, (std::vector<int>{0, 1, 2}));
  // Room again for three, behind the two left: the ring wraps.
  for (int i = 5; i < 8; ++i) {
    auto v = std::make_unique<int>(i);
    ASSERT_TRUE(out.try_write(v));
  }
  auto refused = std::make_unique<int>(99);
  EXPECT_FALSE(out.try_write(refused));
  EXPECT_EQ(in.try_read_each(10, take), 5u);
  EXPECT_EQ(got, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(in.try_read_each(0, take), 0u);
  c.poison();
  EXPECT_THROW(in.try_read_each(1, take), csp::Poisoned);
}

// A writer parked on a full buffer refills the slot a batch read frees, and
// goes on; a rendezvous writer's value is taken straight from it.
TEST(Channel, TryReadEachTakesFromParkedWriters) {
  for (std::size_t capacity : {0u, 2u}) {
    csp::Channel<int> c("c", capacity);
    std::vector<int> got;
    bool written = false;
    csp::Runtime rt(1);
    rt.spawn("writer", 0, [out = c.writer(), &written, capacity]() mutable {
      for (int i = 0; i <= static_cast<int>(capacity); ++i) out.write(i);
      written = true;
    });
    rt.spawn("reader", 0, [in = c.reader(), &got, &written, capacity]() mutable {
      for (int i = 0; i < 10; ++i) csp::yield();  // the writer is parked, its last value in hand
      ASSERT_FALSE(written);
      const auto take = [&got](int& v) { got.push_back(v); };
      EXPECT_EQ(in.try_read_each(100, take), capacity + 1) << "capacity " << capacity;
      for (int i = 0; i < 10 && !written; ++i) csp::yield();
      EXPECT_TRUE(written);
    });
    rt.run();
    std::vector<int> want;
    for (int i = 0; i <= static_cast<int>(capacity); ++i) want.push_back(i);
    EXPECT_EQ(got, want) << "capacity " << capacity;
  }
}

// The room a batch read frees fires an ALT waiting for room.
TEST(Channel, TryReadEachFiresAWaitForRoom) {
  csp::Channel<int> c("c", 2);
  bool room = false;
  csp::Runtime rt(1);
  rt.spawn("writer", 0, [out = c.writer(), &room]() mutable {
    for (int i = 0; i < 2; ++i) out.write(i);
    csp::Alt alt;
    alt.add_room(out);
    alt.select();
    room = true;
  });
  rt.spawn("reader", 0, [in = c.reader(), &room]() mutable {
    for (int i = 0; i < 10; ++i) csp::yield();
    ASSERT_FALSE(room);
    EXPECT_EQ(in.try_read_each(1, [](int& v) { EXPECT_EQ(v, 0); }), 1u);
    for (int i = 0; i < 10 && !room; ++i) csp::yield();
    EXPECT_TRUE(room);
  });
  rt.run();
}

TEST(Channel, ReadForTimesOutWithoutWriter) {
  csp::Channel<int> c("c");
  std::optional<int> got = 1;
  csp::Runtime rt(1);
  rt.spawn("reader", 0, [in = c.reader(), &got]() mutable { got = in.read_for(2ms); });
  rt.run();
  EXPECT_FALSE(got.has_value());
}

TEST(Channel, ReadForReturnsValueWrittenInTime) {
  csp::Channel<int> c("c");
  std::optional<int> got;
  csp::Runtime rt(2);
  rt.spawn("reader", 0, [in = c.reader(), &got]() mutable { got = in.read_for(10s); });
  rt.spawn("writer", 1, [out = c.writer()]() mutable {
    csp::sleep_for(1ms);
    out.write(9);
  });
  rt.run();
  EXPECT_EQ(got, 9);
}

// "Forever" as a timeout must not wrap around into the past and time out at once.
TEST(Channel, ReadForTheLongestDurationWaitsForTheValue) {
  csp::Channel<int> c("c");
  std::optional<int> got;
  csp::Runtime rt(1);
  rt.spawn("writer", 0, [out = c.writer()]() mutable {
    csp::sleep_for(2ms);
    out.write(7);
  });
  rt.spawn("reader", 0, [&, in = c.reader()]() mutable { got = in.read_for(std::chrono::steady_clock::duration::max()); });
  rt.run();
  EXPECT_EQ(got, 7);
}

TEST(Channel, MovesMoveOnlyValues) {
  for (std::size_t capacity : {0u, 2u}) {
    csp::Channel<std::unique_ptr<int>> c("c", capacity);
    int sum = 0;
    csp::Runtime rt(1);
    rt.spawn("writer", 0, [out = c.writer()]() mutable {
      for (int i = 1; i <= 10; ++i) out.write(std::make_unique<int>(i));
    });
    rt.spawn("reader", 0, [in = c.reader(), &sum]() mutable {
      for (int i = 1; i <= 10; ++i) sum += *in.read();
    });
    rt.run();
    EXPECT_EQ(sum, 55);
  }
}

TEST(Channel, PoisonWakesBlockedReader) {
  csp::Channel<int> c("c");
  bool poisoned = false;
  csp::Runtime rt(1);
  rt.spawn("reader", 0, [in = c.reader(), &poisoned]() mutable {
    try {
      in.read();
    } catch (const csp::Poisoned&) {
      poisoned = true;
    }
  });
  rt.spawn("poisoner", 0, [out = c.writer()]() mutable {
    csp::sleep_for(1ms);
    out.poison();
  });
  rt.run();
  EXPECT_TRUE(poisoned);
}

TEST(Channel, PoisonedBufferStillThrows) {
  csp::Channel<int> c("c", 2);
  auto out = c.writer();
  out.write(1);
  c.poison();
  c.poison();
  EXPECT_THROW(c.reader().read(), csp::Poisoned);
  EXPECT_THROW(c.reader().try_read(), csp::Poisoned);
  int v = 2;
  EXPECT_THROW(out.try_write(v), csp::Poisoned);
  EXPECT_TRUE(c.reader().poisoned());
}

// The message of the std::logic_error that use() throws ("" if none).
std::string logic_error_of(const std::function<void()>& use) {
  try {
    use();
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

// Every member of a default-constructed end says what was used unbound,
// again and again (the first error leaves nothing locked or poisoned).
TEST(Channel, UsingAnUnboundEndIsAnErrorThatNamesTheUse) {
  csp::In<int> in;
  csp::Out<int> out;
  int v = 1;
  const std::vector<std::pair<std::string, std::function<void()>>> uses = {
      {"In::read", [&] { in.read(); }},
      {"In::try_read", [&] { in.try_read(); }},
      {"In::read_for", [&] { in.read_for(1ms); }},
      {"In::poisoned", [&] { (void)in.poisoned(); }},
      {"In::poison", [&] { in.poison(); }},
      {"In::name", [&] { (void)in.name(); }},
      {"Out::write", [&] { out.write(1); }},
      {"Out::try_write", [&] { out.try_write(v); }},
      {"Out::poisoned", [&] { (void)out.poisoned(); }},
      {"Out::poison", [&] { out.poison(); }},
      {"Out::name", [&] { (void)out.name(); }},
  };
  for (int round = 0; round < 2; ++round) {
    for (const auto& [use, call] : uses) {
      const std::string what = logic_error_of(call);
      EXPECT_EQ(what.rfind(use + ": the end is bound to no channel", 0), 0u) << use << ": " << what;
    }
  }
}

// An end moved from, by construction or by assignment, is unbound like a
// default-constructed one; the end it moved to works.
TEST(Channel, AnEndMovedFromIsUnbound) {
  csp::Channel<int> c("c", 2);
  csp::In<int> in = c.reader();
  csp::Out<int> out = c.writer();
  csp::In<int> in2(std::move(in));
  csp::Out<int> out2(std::move(out));
  const std::string unbound = ": the end is bound to no channel (default-constructed, or moved from)";
  EXPECT_EQ(logic_error_of([&] { in.read(); }).rfind("In::read" + unbound, 0), 0u);
  EXPECT_EQ(logic_error_of([&] { out.write(1); }).rfind("Out::write" + unbound, 0), 0u);
  out2.write(7);
  EXPECT_EQ(in2.read(), 7);
  csp::In<int> in3;
  csp::Out<int> out3;
  in3 = std::move(in2);
  out3 = std::move(out2);
  EXPECT_EQ(logic_error_of([&] { (void)in2.name(); }).rfind("In::name" + unbound, 0), 0u);
  EXPECT_EQ(logic_error_of([&] { out2.poison(); }).rfind("Out::poison" + unbound, 0), 0u);
  out3.write(8);
  EXPECT_EQ(in3.read(), 8);
  EXPECT_FALSE(in3.poisoned()) << "the moved-from ends' failed uses left the channel alone";
  // A moved-from end takes a new channel's end like any unbound one.
  in = c.reader();
  out3.write(9);
  EXPECT_EQ(in.read(), 9);
}

// An end assigned from a channel after default construction is that
// channel's end, whatever ends of its type were used unbound before.
TEST(Channel, AnEndAssignedAfterDefaultConstructionIsBound) {
  csp::In<int> in;
  csp::Out<int> out;
  EXPECT_THROW(in.try_read(), std::logic_error);
  csp::Channel<int> c("c", 1);
  in = c.reader();
  out = c.writer();
  out.write(5);
  EXPECT_EQ(in.read(), 5);
  EXPECT_EQ(in.name(), "c");
  EXPECT_FALSE(out.poisoned());
}

}  // namespace
