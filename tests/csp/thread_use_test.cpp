// How a runtime thread's time is accounted: running, spinning and sleeping
// add up to its wall time; idle threads spin only with a hardware thread each.
#include <gtest/gtest.h>

#include <atomic>

#include "csp/csp.hpp"

namespace {

using namespace std::chrono_literals;

// An idle thread watches for a wake only while every thread has a hardware
// thread of its own; with more threads than that, a spinning thread would
// hold the core a thread with work is waiting for.
TEST(Runtime, IdleThreadsSpinOnlyWhenEveryThreadHasAHardwareThread) {
  EXPECT_GT(csp::idle_spin(1, 2).count(), 0);
  EXPECT_GT(csp::idle_spin(2, 2).count(), 0);
  EXPECT_GT(csp::idle_spin(8, 0).count(), 0);  // the machine's size unknown
  EXPECT_EQ(csp::idle_spin(3, 2).count(), 0);
  EXPECT_EQ(csp::idle_spin(16, 4).count(), 0);
}

// Thread 1 waits for thread 0, which computes meanwhile: the waiting shows
// as idle time on thread 1, the computing as busy time on thread 0. Thread 0
// computes until 30 ms after thread 1 is about to wait, so however late a
// loaded machine wakes thread 1 after the first message, it then waits for
// 30 ms less the few instructions between its clock reading and its wait.
TEST(Runtime, ThreadUseCountsTimeWithNothingToRun) {
  using Clock = std::chrono::steady_clock;
  csp::Channel<int> started("started");
  csp::Channel<int> done("done");
  std::atomic<Clock::rep> about_to_wait{0};
  csp::Runtime rt(2);
  rt.spawn("busy", 0, [in = started.reader(), out = done.writer(), &about_to_wait]() mutable {
    in.read();
    Clock::rep since;
    while ((since = about_to_wait.load()) == 0) {
    }
    const auto until = Clock::time_point(Clock::duration(since)) + 30ms;
    while (Clock::now() < until) {
    }
    out.write(1);
  });
  rt.spawn("waiting", 1, [out = started.writer(), in = done.reader(), &about_to_wait]() mutable {
    out.write(1);
    about_to_wait.store(Clock::now().time_since_epoch().count());
    in.read();
  });
  rt.run();
  const auto use = rt.thread_use();
  ASSERT_EQ(use.size(), 2u);
  for (const auto& thread : use) {
    EXPECT_GE(thread.seconds, 0.03);
    EXPECT_LE(thread.idle_seconds, thread.seconds);
  }
  EXPECT_GE(use[1].idle_seconds, 0.025);
  EXPECT_LE(use[0].idle_seconds, use[0].seconds - 0.025);
}

// The three parts of a thread's time are cut at the same clock readings,
// so they add up to its wall time; thread 0 computes for 60 ms, which shows
// as running time, while thread 1 waits for it, first spinning, then asleep.
TEST(Runtime, ThreadUseSplitAddsUpToWallTime) {
  using Clock = std::chrono::steady_clock;
  csp::Channel<int> started("started");
  csp::Channel<int> done("done");
  csp::Runtime rt(2);
  rt.spawn("busy", 0, [in = started.reader(), out = done.writer()]() mutable {
    in.read();
    const auto until = Clock::now() + 60ms;
    while (Clock::now() < until) {
    }
    out.write(1);
  });
  rt.spawn("waiting", 1, [out = started.writer(), in = done.reader()]() mutable {
    out.write(1);
    in.read();
  });
  rt.run();
  const auto use = rt.thread_use();
  ASSERT_EQ(use.size(), 2u);
  for (const auto& t : use) {
    EXPECT_NEAR(t.running_seconds + t.spinning_seconds + t.sleeping_seconds, t.seconds, 1e-6);
    EXPECT_NEAR(t.idle_seconds, t.spinning_seconds + t.sleeping_seconds, 1e-6);
    EXPECT_GE(t.running_seconds, 0);
    EXPECT_GE(t.spinning_seconds, 0);
    EXPECT_GE(t.sleeping_seconds, 0);
    EXPECT_GT(t.cpu_seconds, 0);
    EXPECT_LE(t.cpu_seconds, t.seconds + 1e-3);
    EXPECT_LE(t.sleeps, t.waits);
  }
  EXPECT_GE(use[0].running_seconds, 0.06);
  EXPECT_GE(use[1].waits, 1u);
  // Thread 1 waits while thread 0 spins 60 ms, far past any spin, so it
  // sleeps; half of that at least, however long the OS kept thread 1 from
  // starting its wait.
  EXPECT_GE(use[1].sleeps, 1u);
  EXPECT_GE(use[1].spinning_seconds + use[1].sleeping_seconds, 0.03);
}

// A thread whose processes never wait runs the whole time: no idle wait,
// all of its time is running time.
TEST(Runtime, ThreadUseOfAThreadThatNeverWaitsIsAllRunning) {
  using Clock = std::chrono::steady_clock;
  csp::Runtime rt(1);
  rt.spawn("busy", 0, [] {
    const auto until = Clock::now() + 10ms;
    while (Clock::now() < until) {
    }
  });
  rt.run();
  const auto use = rt.thread_use();
  ASSERT_EQ(use.size(), 1u);
  EXPECT_EQ(use[0].waits, 0u);
  EXPECT_EQ(use[0].spinning_seconds, 0);
  EXPECT_EQ(use[0].sleeping_seconds, 0);
  EXPECT_NEAR(use[0].running_seconds, use[0].seconds, 1e-6);
  EXPECT_GE(use[0].running_seconds, 0.01);
}

}  // namespace
