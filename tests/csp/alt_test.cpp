// ALT: fairness, priority, boolean guards, timeout, SKIP, poisoned inputs,
// room guards on buffered outputs — each for both ways of waiting (relinking
// records on every channel, and the doorbell); then what only the doorbell
// has: one watcher per channel end, released when the ALT goes.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "csp/csp.hpp"

// How gtest shows the parameter, in test names and failures.
namespace csp {
void PrintTo(Alt::Waiting waiting, std::ostream* out) {
  *out << (waiting == Alt::Waiting::relink ? "relink" : "doorbell");
}
}  // namespace csp

namespace {

using namespace std::chrono_literals;

class Alt : public ::testing::TestWithParam<csp::Alt::Waiting> {};

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

// Moves `count` values from r to w holding at most one, selecting over the
// input while it holds none and over room in w while it holds one.
void forward_with_room_guard(csp::In<int> r, csp::Out<int> w, int count, csp::Alt::Waiting waiting) {
  csp::Alt alt(waiting);
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
}

// Reads `count` values; true if they were 1, 2, ..., count.
bool reads_one_to_count(csp::In<int> r, int count) {
  bool ordered = true;
  for (int k = 1; k <= count; ++k) ordered = r.read() == k && ordered;
  return ordered;
}

TEST_P(Alt, FairSelectStarvesNoGuard) {
  const csp::Alt::Waiting waiting = GetParam();
  constexpr int n = 4;
  constexpr int selections = 10000;
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, n, selections);  // every writer always ready
  std::array<int, n> chosen{};
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
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

// More guards than fit one word of the doorbell's marks: with every guard
// ready, fair selects take them in turn, across the word boundaries.
TEST_P(Alt, FairSelectTakesManyReadyGuardsInTurn) {
  constexpr int n = 130;
  std::vector<csp::Channel<int>> chans;
  for (int i = 0; i < n; ++i) chans.emplace_back("in" + std::to_string(i), 2);
  csp::Alt alt(GetParam());
  std::vector<csp::In<int>> ins;
  for (int i = 0; i < n; ++i) {
    chans[i].writer().write(i);
    chans[i].writer().write(i);
    ins.push_back(chans[i].reader());
    alt.add_input(ins.back());
  }
  for (int s = 0; s < 2 * n; ++s) {
    const std::size_t i = alt.select();
    ASSERT_EQ(i, static_cast<std::size_t>(s % n)) << "select " << s;
    EXPECT_EQ(ins[i].read(), s % n);
  }
}

// A guard found not ready, then disabled while its channel becomes ready, is
// chosen once enabled again, with nothing more written.
TEST_P(Alt, InputThatBecameReadyWhileDisabledIsChosenOnceEnabled) {
  csp::Channel<int> c("c", 1);
  csp::Alt alt(GetParam());
  auto in = c.reader();
  const std::size_t input = alt.add_input(in);
  const std::size_t skip = alt.add_skip();
  EXPECT_EQ(alt.pri_select(), skip);  // c looked at and found empty
  alt.enable(input, false);
  c.writer().write(7);
  EXPECT_EQ(alt.pri_select(), skip);
  alt.enable(input, true);
  EXPECT_EQ(alt.pri_select(), input);
  EXPECT_EQ(in.read(), 7);
  EXPECT_EQ(alt.pri_select(), skip);
}

TEST_P(Alt, PriSelectPrefersLowestReadyIndex) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, 3, 10, 10);
  std::vector<std::size_t> chosen;
  rt.spawn("alt", 0, [&] {
    csp::sleep_for(1ms);  // let every writer fill its buffer
    csp::Alt alt(waiting);
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

TEST_P(Alt, DisabledGuardIsNeverChosen) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Runtime rt(1);
  auto chans = spawn_writers(rt, 2, 100);
  std::vector<std::size_t> chosen;
  rt.spawn("alt", 0, [&] {
    csp::sleep_for(1ms);
    csp::Alt alt(waiting);
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

TEST_P(Alt, GuardsMayChangeBetweenSelects) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> a("a", 4);
  csp::Channel<int> b("b", 4);
  for (int i = 0; i < 4; ++i) {
    a.writer().write(i);
    b.writer().write(i);
  }
  csp::Alt alt(waiting);
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

// poll() is a PRI ALT with SKIP last: the lowest ready guard, or nothing,
// and it never waits, also with no guard enabled at all.
TEST_P(Alt, PollTakesTheLowestReadyGuardOrNothing) {
  csp::Channel<int> a("a", 4), b("b", 4);
  csp::Alt alt(GetParam());
  auto ia = a.reader();
  auto ib = b.reader();
  const std::size_t ga = alt.add_input(ia), gb = alt.add_input(ib);
  EXPECT_FALSE(alt.poll().has_value());
  b.writer().write(1);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(gb));
  a.writer().write(2);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(ga));  // twice: nothing read yet
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(ga));
  EXPECT_EQ(ia.read(), 2);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(gb));
  alt.enable(gb, false);
  EXPECT_FALSE(alt.poll().has_value());  // b still holds 1, but its guard is off
  alt.enable(ga, false);
  EXPECT_FALSE(alt.poll().has_value());  // no guard at all: no STOP error, just nothing
  alt.enable(gb, true);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(gb));
  EXPECT_EQ(ib.read(), 1);
  EXPECT_FALSE(alt.poll().has_value());
}

// A select after polls that found nothing still wakes on the next write, so
// a process may poll until nothing is ready and then wait.
TEST_P(Alt, SelectAfterEmptyPollsWakesOnTheNextWrite) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Runtime rt(2);
  csp::Channel<int> c("c", 2);
  std::vector<int> got;
  rt.spawn("reader", 0, [&, in = c.reader()]() mutable {
    csp::Alt alt(waiting);
    const std::size_t g = alt.add_input(in);
    for (int k = 0; k < 200; ++k) {
      while (alt.poll()) got.push_back(in.read());
      if (got.size() == 200) break;
      EXPECT_EQ(alt.select(), g);
      got.push_back(in.read());
      if (got.size() == 200) break;
    }
  });
  rt.spawn("writer", 1, [out = c.writer()]() mutable {
    for (int i = 0; i < 200; ++i) out.write(i);
  });
  rt.run();
  ASSERT_EQ(got.size(), 200u);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(got[i], i);
}

TEST_P(Alt, AllGuardsDisabledIsAnError) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  csp::Alt alt(waiting);
  alt.enable(alt.add_input(c.reader()), false);
  EXPECT_THROW(alt.select(), std::logic_error);
}

TEST_P(Alt, TimeoutFiresWhenNothingElseIsReady) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  std::size_t chosen = 99;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
    alt.add_input(c.reader());
    const std::size_t t = alt.add_timeout(2ms);
    chosen = alt.select();
    EXPECT_EQ(chosen, t);
  });
  rt.run();
  EXPECT_EQ(chosen, 1u);
}

TEST_P(Alt, InputBeatsLaterTimeout) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  int got = 0;
  csp::Runtime rt(2);
  rt.spawn("writer", 1, [out = c.writer()]() mutable {
    csp::sleep_for(1ms);
    out.write(5);
  });
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
    auto in = c.reader();
    alt.add_input(in);
    alt.add_timeout(10s);
    ASSERT_EQ(alt.select(), 0u);
    got = in.read();
  });
  rt.run();
  EXPECT_EQ(got, 5);
}

// "Forever" as a timeout must not wrap around into the past and fire at once.
TEST_P(Alt, ATimeoutOfTheLongestDurationNeverFires) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  int got = 0;
  csp::Runtime rt(1);
  rt.spawn("writer", 0, [out = c.writer()]() mutable {
    csp::sleep_for(2ms);
    out.write(5);
  });
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
    auto in = c.reader();
    alt.add_input(in);
    alt.add_timeout(std::chrono::steady_clock::duration::max());
    ASSERT_EQ(alt.select(), 0u);
    got = in.read();
  });
  rt.run();
  EXPECT_EQ(got, 5);
}

TEST_P(Alt, SkipIsAlwaysReady) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  csp::Alt alt(waiting);
  alt.add_input(c.reader());
  const std::size_t skip = alt.add_skip();
  EXPECT_EQ(alt.pri_select(), skip);
  EXPECT_EQ(alt.select(), skip);
}

TEST_P(Alt, PoisonedInputIsReadyAndItsReadThrows) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> c("c");
  bool threw = false;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
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

TEST_P(Alt, BufferedInputWakesParkedAlt) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> a("a", 4);
  csp::Channel<int> b("b");
  int sum = 0;
  csp::Runtime rt(2);
  rt.spawn("writer", 1, [out = a.writer()]() mutable {
    for (int i = 1; i <= 100; ++i) out.write(i);
  });
  rt.spawn("alt", 0, [&] {
    csp::Alt alt(waiting);
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

TEST_P(Alt, CrossThreadStressLosesNothing) {
  const csp::Alt::Waiting waiting = GetParam();
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
    csp::Alt alt(waiting);
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

TEST_P(Alt, RoomGuardFiresOnlyOnceAReaderFreesASlot) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> full("full", 2);
  std::vector<std::string> events;
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&, out = full.writer()]() mutable {
    out.write(1);
    out.write(2);
    int three = 3;
    EXPECT_FALSE(out.try_write(three));
    csp::Alt alt(waiting);
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

TEST_P(Alt, RoomGuardOnAnUnbufferedChannelIsAnError) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> rendezvous("rendezvous");
  csp::Alt alt(waiting);
  EXPECT_THROW(alt.add_room(rendezvous.writer()), std::logic_error);
}

TEST_P(Alt, AnUnboundEndIsNoGuard) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Alt alt(waiting);
  try {
    alt.add_input(csp::In<int>());
    ADD_FAILURE() << "an unbound input was accepted";
  } catch (const std::logic_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("Alt::add_input: the end is bound to no channel", 0), 0u) << e.what();
  }
  try {
    alt.add_room(csp::Out<int>());
    ADD_FAILURE() << "an unbound room guard was accepted";
  } catch (const std::logic_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("Alt::add_room: the end is bound to no channel", 0), 0u) << e.what();
  }
  EXPECT_EQ(alt.guard_count(), 0u);
}

TEST_P(Alt, PoisonedRoomGuardIsReadyAndTheWriteThrows) {
  const csp::Alt::Waiting waiting = GetParam();
  csp::Channel<int> full("full", 1);
  csp::Runtime rt(1);
  rt.spawn("alt", 0, [&, out = full.writer()]() mutable {
    out.write(1);
    csp::Alt alt(waiting);
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
TEST_P(Alt, ForwarderWithRoomGuardLosesNothingAcrossThreads) {
  const csp::Alt::Waiting waiting = GetParam();
  constexpr int count = 20000;
  csp::Channel<int> in("in", 1), out("out", 2);
  bool ordered = false;
  csp::Runtime rt(2);
  rt.spawn("source", 0, [w = in.writer()]() mutable {
    for (int k = 1; k <= count; ++k) w.write(k);
  });
  rt.spawn("forwarder", 0, [r = in.reader(), w = out.writer(), waiting] {
    forward_with_room_guard(r, w, count, waiting);
  });
  rt.spawn("sink", 1, [&ordered, r = out.reader()] { ordered = reads_one_to_count(r, count); });
  rt.run();
  EXPECT_TRUE(ordered);
}

INSTANTIATE_TEST_SUITE_P(Waiting, Alt, ::testing::Values(csp::Alt::Waiting::relink, csp::Alt::Waiting::doorbell),
                         [](const ::testing::TestParamInfo<csp::Alt::Waiting>& info) {
                           return info.param == csp::Alt::Waiting::relink ? "relink" : "doorbell";
                         });

TEST(AltDoorbell, OneDoorbellAltPerChannelEnd) {
  csp::Channel<int> c("c", 1);
  csp::Alt reader(csp::Alt::Waiting::doorbell);
  reader.add_input(c.reader());
  csp::Alt other(csp::Alt::Waiting::doorbell);
  EXPECT_THROW(other.add_input(c.reader()), std::logic_error);
  // The other end is free: the writer's ALT may watch for room.
  csp::Alt writer(csp::Alt::Waiting::doorbell);
  EXPECT_NO_THROW(writer.add_room(c.writer()));
  EXPECT_THROW(other.add_room(c.writer()), std::logic_error);
}

// A doorbell ALT registers one mark per channel end, so it takes a channel
// once; the error says so rather than blame another ALT.
TEST(AltDoorbell, AChannelGuardedTwiceIsAnErrorThatSaysSo) {
  csp::Channel<int> c("c");
  csp::Alt alt(csp::Alt::Waiting::doorbell);
  alt.add_input(c.reader());
  try {
    alt.add_input(c.reader());
    ADD_FAILURE() << "a second guard on 'c' was accepted";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("guarded twice by one doorbell ALT"), std::string::npos) << e.what();
  }
}

TEST(AltDoorbell, DestroyedAltReleasesItsChannels) {
  csp::Channel<int> c("c", 2);
  {
    csp::Alt gone(csp::Alt::Waiting::doorbell);
    gone.add_input(c.reader());
    gone.add_room(c.writer());
  }
  // Writes and reads no longer ring the freed bell (ASan checks), and the
  // ends may be watched again.
  int v = 1;
  EXPECT_TRUE(c.writer().try_write(v));
  EXPECT_EQ(c.reader().read(), 1);
  csp::Alt again(csp::Alt::Waiting::doorbell);
  EXPECT_NO_THROW(again.add_input(c.reader()));
}

// Forwarders in a line, each selecting over its input and the room in its
// output, on alternating threads: every channel between two of them is
// watched at both ends, by the bells of two ALTs on different threads.
// A channel whose guard is off rings without waking its ALT, but its mark
// stays: once the guard is on again, the next poll finds the channel ready.
TEST(AltDoorbell, AChannelThatRangWhileItsGuardWasOffIsSeenWhenItIsOn) {
  csp::Channel<int> a("a", 4), b("b", 4);
  csp::Alt alt(csp::Alt::Waiting::doorbell);
  auto ia = a.reader();
  auto ib = b.reader();
  const std::size_t ga = alt.add_input(ia), gb = alt.add_input(ib);
  alt.enable(ga, false);
  EXPECT_FALSE(alt.poll().has_value());  // a's guard is off, and no longer armed
  a.writer().write(7);
  EXPECT_FALSE(alt.poll().has_value());
  alt.enable(ga, true);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(ga));
  EXPECT_EQ(ia.read(), 7);
  EXPECT_FALSE(alt.poll().has_value());
  b.writer().write(8);
  EXPECT_EQ(alt.poll(), std::optional<std::size_t>(gb));
}

// Across threads: an ALT parked with one guard off is woken by the guard
// that is on, never wrongly chosen for the one that is off, and takes the
// other's values once it turns it on.
TEST(AltDoorbell, AGuardThatIsOffNeverWinsAcrossThreads) {
  constexpr int count = 2000;
  csp::Channel<int> off("off", 4), on("on", 1);
  std::vector<int> from_on, from_off;
  csp::Runtime rt(2);
  rt.spawn("reader", 0, [&, io = off.reader(), in = on.reader()]() mutable {
    csp::Alt alt(csp::Alt::Waiting::doorbell);
    const std::size_t g_off = alt.add_input(io), g_on = alt.add_input(in);
    alt.enable(g_off, false);
    while (from_on.size() < count) {
      const std::size_t g = alt.select();
      ASSERT_EQ(g, g_on);
      from_on.push_back(in.read());
    }
    alt.enable(g_off, true);
    alt.enable(g_on, false);
    while (from_off.size() < 4) {
      ASSERT_EQ(alt.select(), g_off);
      from_off.push_back(io.read());
    }
  });
  rt.spawn("writer", 1, [wo = off.writer(), wi = on.writer()]() mutable {
    for (int k = 0; k < 4; ++k) wo.write(k);
    for (int k = 0; k < count; ++k) wi.write(k);
  });
  rt.run();
  EXPECT_EQ(from_on.size(), std::size_t{count});
  EXPECT_EQ(from_off, (std::vector<int>{0, 1, 2, 3}));
}

TEST(AltDoorbell, LineOfForwardersLosesNothingAcrossThreads) {
  constexpr int stages = 4;
  constexpr int count = 20000;
  std::vector<csp::Channel<int>> links;
  for (int i = 0; i <= stages; ++i) links.emplace_back("link" + std::to_string(i), 1);
  bool ordered = false;
  csp::Runtime rt(2);
  rt.spawn("source", 0, [w = links[0].writer()]() mutable {
    for (int k = 1; k <= count; ++k) w.write(k);
  });
  for (int i = 0; i < stages; ++i)
    rt.spawn("forwarder" + std::to_string(i), static_cast<unsigned>(i % 2),
             [r = links[i].reader(), w = links[i + 1].writer()] {
               forward_with_room_guard(r, w, count, csp::Alt::Waiting::doorbell);
             });
  rt.spawn("sink", 1, [&ordered, r = links[stages].reader()] { ordered = reads_one_to_count(r, count); });
  rt.run();
  EXPECT_TRUE(ordered);
}

}  // namespace
