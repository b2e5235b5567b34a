// ALT: fairness, priority, boolean guards, timeout, SKIP, poisoned inputs,
// room guards on buffered outputs.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <stdexcept>
#include <vector>

#include "csp/csp.hpp"

namespace {

using namespace std::chrono_literals;

// n writers, each writing `count` values of its own index into its channel.
std::vector<csp::Channel<int>> spawn_writers(csp::Runtime& rt, int n, int count, std::size_t capacity = 0) {
  std::vector<csp::Channel<int>> chans;
  for (int i = 0; i < n; ++i) chans.emplace_back("in" + std::to_string(i), capacity);
  for (int i = 0; i < n; ++i) {
    rt.spawn("writer" + std::to_string(i), 0, [out = chans[i].writer(), i, count]() mutable {
      for (int k = 0; k < count; ++k) out.write(i);
    });
  }
  return chans;
}

TEST(Alt, FairSelectStarvesNoGuard) {
  constexpr int n = 4;
  constexpr int selections = 10000;
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, n, selections);  // every writer always ready
  std::array<int, n> chosen{};
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    std::vector<csp::In<int>> ins;
    for (auto& c : chans) ins.push_back(c.reader());
    for (auto& in : ins) alt.add_input(in);
    for (int s = 0; s < selections; ++s) {
      const std::size_t i = alt.select();
      EXPECT_EQ(ins[i].read(), static_cast<int>(i));
      ++chosen[i];
    }
    for (auto& c : chans) c.poison();
  });
  rt.run();
  for (int c : chosen) EXPECT_EQ(c, selections / n);
}

TEST(Alt, PriSelectPrefersLowestReadyIndex) {
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, 3, 10, 10);
  std::vector<std::size_t> chosen;
  rt.spawn("alt", 0, [&] {
    csp::sleep_for(1ms);  // let every writer fill its buffer
    csp::Alt alt;
    std::vector<csp::In<int>> ins;
    for (auto& c : chans) ins.push_back(c.reader());
    for (auto& in : ins) alt.add_input(in);
    for (int s = 0; s < 5; ++s) {
      const std::size_t i = alt.pri_select();
      ins[i].read();
      chosen.push_back(i);
    }
    for (auto& c : chans) c.poison();
  });
  rt.run();
  EXPECT_EQ(chosen, std::vector<std::size_t>(5, 0));
}

TEST(Alt, DisabledGuardIsNeverChosen) {
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, 2, 100);
  std::vector<std::size_t> chosen;
  rt.spawn("alt", 0, [&] {
    csp::sleep_for(1ms);
    csp::Alt alt;
    auto a = chans[0].reader();
    auto b = chans[1].reader();
    alt.add_input(a);
    alt.add_input(b);
    alt.enable(0, false);
    for (int s = 0; s < 5; ++s) {
      const std::size_t i = alt.pri_select();
      (i == 0 ? a : b).read();
      chosen.push_back(i);
    }
    for (auto& c : chans) c.poison();
  });
  rt.run();
  EXPECT_EQ(chosen, std::vector<std::size_t>(5, 1));
}

TEST(Alt, GuardsMayChangeBetweenSelects) {
  csp::Channel<int> a("a", 4);
  csp::Channel<int> b("b", 4);
  for (int i = 0; i < 4; ++i) {
    a.writer().write(i);
    b.writer().write(i);
  }
  csp::Alt alt;
  auto ia = a.reader();
  auto ib = b.reader();
  alt.add_input(ia);
  alt.add_input(ib);
  alt.enable(0, false);
  EXPECT_EQ(alt.pri_select(), 1u);
  ib.read();
  alt.enable(0, true);
  EXPECT_EQ(alt.pri_select(), 0u);
  ia.read();
  const std::size_t skip = alt.add_skip();
  alt.enable(0, false);
  alt.enable(1, false);
  EXPECT_EQ(alt.pri_select(), skip);
}

TEST(Alt, AllGuardsDisabledIsAnError) {
  csp::Channel<int> c("c");
  csp::Alt alt;
  alt.enable(alt.add_input(c.reader()), false);
  EXPECT_THROW(alt.select(), std::logic_error);
}

TEST(Alt, TimeoutFiresWhenNothingElseIsReady) {
  csp::Channel<int> c("c");
  std::size_t chosen = 99;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    alt.add_input(c.reader());
    const std::size_t t = alt.add_timeout(2ms);
    chosen = alt.select();
    EXPECT_EQ(chosen, t);
  });
  rt.run();
  EXPECT_EQ(chosen, 1u);
}

TEST(Alt, InputBeatsLaterTimeout) {
  csp::Channel<int> c("c");
  int got = 0;
  csp::Runtime rt(2);
  rt.spawn("writer", 1, [out = c.writer()]() mutable {
    csp::sleep_for(1ms);
    out.write(5);
  });
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    auto in = c.reader();
    alt.add_input(in);
    alt.add_timeout(10s);
    ASSERT_EQ(alt.select(), 0u);
    got = in.read();
  });
  rt.run();
  EXPECT_EQ(got, 5);
}

TEST(Alt, SkipIsAlwaysReady) {
  csp::Channel<int> c("c");
  csp::Alt alt;
  alt.add_input(c.reader());
  const std::size_t skip = alt.add_skip();
  EXPECT_EQ(alt.pri_select(), skip);
  EXPECT_EQ(alt.select(), skip);
}

TEST(Alt, PoisonedInputIsReadyAndItsReadThrows) {
  csp::Channel<int> c("c");
  bool threw = false;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    auto in = c.reader();
    alt.add_input(in);
    ASSERT_EQ(alt.select(), 0u);
    try {
      in.read();
    } catch (const csp::Poisoned&) {
      threw = true;
    }
  });
  rt.spawn("poisoner", 0, [&] {
    csp::sleep_for(1ms);
    c.poison();
  });
  rt.run();
  EXPECT_TRUE(threw);
}

TEST(Alt, BufferedInputWakesParkedAlt) {
  csp::Channel<int> a("a", 4);
  csp::Channel<int> b("b");
  int sum = 0;
  csp::Runtime rt(2);
  rt.spawn("writer", 1, [out = a.writer()]() mutable {
    for (int i = 1; i <= 100; ++i) out.write(i);
  });
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    auto ia = a.reader();
    auto ib = b.reader();
    alt.add_input(ib);
    alt.add_input(ia);
    for (int s = 0; s < 100; ++s) {
      ASSERT_EQ(alt.select(), 1u);
      sum += ia.read();
    }
  });
  rt.run();
  EXPECT_EQ(sum, 5050);
}

TEST(Alt, CrossThreadStressLosesNothing) {
  constexpr int writers = 8;
  constexpr int per_writer = 2000;
  std::vector<csp::Channel<int>> chans;
  for (int i = 0; i < writers; ++i) chans.emplace_back("w" + std::to_string(i), i % 2);
  long sum = 0;
  csp::Runtime rt(2);
  for (int i = 0; i < writers; ++i) {
    rt.spawn("writer" + std::to_string(i), i, [out = chans[i].writer()]() mutable {
      for (int k = 1; k <= per_writer; ++k) out.write(k);
    });
  }
  rt.spawn("alt", 0, [&] {
    csp::Alt alt;
    std::vector<csp::In<int>> ins;
    for (auto& c : chans) ins.push_back(c.reader());
    for (auto& in : ins) alt.add_input(in);
    const std::size_t timeout = alt.add_timeout(1ms);
    for (int got = 0; got < writers * per_writer;) {
      const std::size_t i = alt.select();
      if (i == timeout) continue;  // a timed wait racing the writers
      sum += ins[i].read();
      ++got;
    }
  });
  rt.run();
  EXPECT_EQ(sum, long{writers} * per_writer * (per_writer + 1) / 2);
}

TEST(Alt, RoomGuardFiresOnlyOnceAReaderFreesASlot) {
  csp::Channel<int> full("full", 2);
  std::vector<std::string> events;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&, out = full.writer()]() mutable {
    out.write(1);
    out.write(2);
    int three = 3;
    EXPECT_FALSE(out.try_write(three));
    csp::Alt alt;
    alt.add_room(out);
    events.push_back("alt waits");
    EXPECT_EQ(alt.select(), 0u);
    events.push_back("alt woken");
    EXPECT_TRUE(out.try_write(three));
  });
  rt.spawn("reader", 0, [&, in = full.reader()]() mutable {
    csp::sleep_for(1ms);
    events.push_back("reader reads " + std::to_string(in.read()));
    EXPECT_EQ(in.read(), 2);
    EXPECT_EQ(in.read(), 3);
  });
  rt.run();
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0], "alt waits");
  EXPECT_EQ(events[1], "reader reads 1");
  EXPECT_EQ(events[2], "alt woken");
}

TEST(Alt, RoomGuardOnAnUnbufferedChannelIsAnError) {
  csp::Channel<int> rendezvous("rendezvous");
  csp::Alt alt;
  EXPECT_THROW(alt.add_room(rendezvous.writer()), std::logic_error);
}

TEST(Alt, PoisonedRoomGuardIsReadyAndTheWriteThrows) {
  csp::Channel<int> full("full", 1);
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&, out = full.writer()]() mutable {
    out.write(1);
    csp::Alt alt;
    alt.add_room(out);
    EXPECT_EQ(alt.select(), 0u);
    EXPECT_THROW(out.write(2), csp::Poisoned);
  });
  rt.spawn("poisoner", 0, [&] {
    csp::sleep_for(1ms);
    full.poison();
  });
  rt.run();
}

// A forwarder that never blocks on output, as a router does: it holds back
// at most one value, reading no input until room for it appears. Across two
// threads every value arrives once and in order.
TEST(Alt, ForwarderWithRoomGuardLosesNothingAcrossThreads) {
  constexpr int count = 20000;
  csp::Channel<int> in("in", 1), out("out", 2);
  long sum = 0;
  int last = 0;
  bool ordered = true;
  csp::Runtime rt(2);
  rt.spawn("source", 0, [w = in.writer()]() mutable {
    for (int k = 1; k <= count; ++k) w.write(k);
  });
  rt.spawn("forwarder", 0, [r = in.reader(), w = out.writer()]() mutable {
    csp::Alt alt;
    const std::size_t input = alt.add_input(r);
    const std::size_t room = alt.add_room(w);
    int held = 0;
    bool holding = false;
    for (int moved = 0; moved < count;) {
      alt.enable(input, !holding);
      alt.enable(room, holding);
      if (alt.select() == input) {
        held = r.read();
        holding = true;
      }
      if (w.try_write(held)) {
        holding = false;
        ++moved;
      }
    }
  });
  rt.spawn("sink", 1, [&, r = out.reader()]() mutable {
    for (int k = 1; k <= count; ++k) {
      const int v = r.read();
      ordered = ordered && v == last + 1;
      last = v;
      sum += v;
    }
  });
  rt.run();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(sum, long{count} * (count + 1) / 2);
}

}  // namespace
