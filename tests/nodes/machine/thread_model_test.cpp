// The thread model's arithmetic: what it predicts for one thread, that its
// fits give back the times they were fitted to, and the figures of
// docs/performance.md's table of predictions for 16 threads.
#include "nodes/machine/thread_model.hpp"

#include <gtest/gtest.h>

namespace nodes {
namespace {

// Rings4 on 16 nodes as docs/performance.md's predictions take it: W and M
// of one build, L = 2 us, c from the middle of the fitted range.
ThreadModel rings4_16() {
  ThreadModel m;
  m.work_seconds = 0.871;
  m.misses = 279000;
  m.crossing_seconds = 1e-6;
  m.latency_seconds = 2e-6;
  m.pixel_computers = 16;
  return m;
}

TEST(ThreadModel, OneThreadIsTheWorkAlone) {
  const ThreadModel::Parts p = rings4_16().parts(1);
  EXPECT_DOUBLE_EQ(p.work, 0.871);
  EXPECT_DOUBLE_EQ(p.crossings, 0);
  EXPECT_DOUBLE_EQ(p.idle, 0);
}

TEST(ThreadModel, SixteenThreadsOfOnePixelComputerEachIdleAtEveryMiss) {
  // r = 4, k = 1: each thread's one pixel computer waits R = 4 L at each of its misses.
  const ThreadModel::Parts p = rings4_16().parts(16);
  EXPECT_NEAR(p.work, 0.871 / 16, 1e-12);
  EXPECT_NEAR(p.crossings, 4 * 279000 * 1e-6 / 16, 1e-12);
  EXPECT_NEAR(p.idle, 279000.0 / 16 * 8e-6, 1e-12);  // 17 400 misses a thread, 8 us each: 0.14 s
  EXPECT_NEAR(rings4_16().predict(16), p.work + p.crossings + p.idle, 1e-12);
}

TEST(ThreadModel, OtherPixelComputersHideTheWaitWhenTheyComputeLongerThanItLasts) {
  ThreadModel m = rings4_16();
  m.pixel_computers = 64;  // k = 4 on 16 threads; (k - 1) t = 3 * 3.1 us > R = 8 us
  EXPECT_DOUBLE_EQ(m.parts(16).idle, 0);
  m.latency_seconds = 4e-6;  // R = 16 us > 9.4 us: the rest idles
  EXPECT_NEAR(m.parts(16).idle, 279000.0 / 16 * (16e-6 - 3 * 0.871 / 279000), 1e-12);
}

TEST(ThreadModel, MoreThreadsThanPixelComputersCountAsThatMany) {
  EXPECT_DOUBLE_EQ(rings4_16().predict(64), rings4_16().predict(16));
  ThreadModel idle_free = rings4_16();
  idle_free.latency_seconds = 0;
  EXPECT_LT(idle_free.predict(16), idle_free.predict(8));
}

TEST(ThreadModel, TheCrossingFitGivesBackTheTwoThreadTime) {
  ThreadModel m = rings4_16();
  m.crossing_seconds = ThreadModel::fit_crossing(0.540, 0.387, 269000);
  m.work_seconds = 0.540;
  m.misses = 269000;
  EXPECT_NEAR(m.crossing_seconds, 0.87e-6, 0.01e-6);  // the figure of the docs' fit
  EXPECT_DOUBLE_EQ(m.parts(2).idle, 0);              // eight pixel computers a thread hide L
  EXPECT_NEAR(m.predict(2), 0.387, 1e-12);
}

TEST(ThreadModel, TheLatencyFitGivesBackTwoNodesOnTwoThreads) {
  ThreadModel two;
  two.work_seconds = 0.699;
  two.misses = 150000;
  two.pixel_computers = 2;
  two.crossing_seconds = 0.8e-6;
  two.latency_seconds = ThreadModel::fit_latency(0.699, 0.715, 150000, 0.8e-6);
  EXPECT_GT(two.latency_seconds, 0);
  EXPECT_NEAR(two.predict(2), 0.715, 1e-12);
}

TEST(ThreadModel, FitsNeverGoBelowZeroNorDivideByNoMisses) {
  EXPECT_DOUBLE_EQ(ThreadModel::fit_crossing(1.0, 0.4, 1000), 0);  // faster than half: no cost to fit
  EXPECT_DOUBLE_EQ(ThreadModel::fit_latency(1.0, 0.5, 1000, 1e-6), 0);
  EXPECT_DOUBLE_EQ(ThreadModel::fit_crossing(1.0, 0.6, 0), 0);
  EXPECT_DOUBLE_EQ(ThreadModel::fit_latency(1.0, 0.6, 0, 1e-6), 0);
  ThreadModel none;
  none.work_seconds = 1.0;
  none.pixel_computers = 4;
  EXPECT_DOUBLE_EQ(none.predict(4), 0.25);
}

}  // namespace
}  // namespace nodes
