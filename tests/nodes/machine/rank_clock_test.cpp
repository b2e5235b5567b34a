// Rank 0's estimate of another rank's clock (rank_clock.hpp): two ranks of
// one process whose run clocks began a known time apart, so the offset the
// pings find can be held against the true one. Its error is how far a
// replay across ranks may misplace a rank's events: the test records it in
// nanoseconds (a few hundred inside one process on the 2-core machine).
#include "nodes/machine/rank_clock.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace {

using namespace std::chrono_literals;

// A run clock begun at `started`, recording nothing.
class Clock final : public nodes::RouteRecorder {
 public:
  explicit Clock(std::chrono::steady_clock::time_point started) : RouteRecorder(0, false, started) {}
  nodes::RouteLog& route_log(nodes::NodeId) override { return log_; }

 private:
  nodes::RouteLog log_;
};

// Each answer is read between a ping's sending and the answer's arrival,
// so the error is at most half the quickest round trip, however slow the
// ranks (sanitizers, a loaded host) make it.
TEST(RankClock, TheOffsetFoundIsTheTrueOneWithinHalfTheQuickestRoundTrip) {
  const auto now = std::chrono::steady_clock::now();
  for (const auto apart : {250ms, -40ms}) {
    SCOPED_TRACE(apart.count());
    // Rank 1 began `apart` before rank 0: its clock reads that much more.
    const Clock zero(now), one(now - apart);
    nodes::LocalTransportGroup group(2);
    std::thread answering([&] { nodes::answer_clock(group.rank(1), one); });
    const nodes::ClockOffset found = nodes::clock_offset(group.rank(0), 1, zero);
    answering.join();
    const double truth = -std::chrono::duration<double>(apart).count();
    const double error = std::abs(found.offset - truth);
    RecordProperty("error_nanoseconds_" + std::to_string(apart.count()), static_cast<int>(error * 1e9));
    RecordProperty("round_trip_nanoseconds_" + std::to_string(apart.count()),
                   static_cast<int>(std::min(found.round_trip, 1.0) * 1e9));
    EXPECT_GT(found.round_trip, 0.0);
    EXPECT_LE(error, found.round_trip / 2 + 1e-9)
        << "offset " << found.offset << " s, true " << truth << " s, round trip " << found.round_trip << " s";
  }
}

TEST(RankClock, TheBudgetIsSharedOutWhole) {
  for (const std::uint64_t total : {0u, 1u, 7u, 1000u})
    for (const int ranks : {1, 2, 3, 5}) {
      std::uint64_t sum = 0;
      for (int r = 0; r < ranks; ++r) {
        const std::uint64_t b = nodes::rank_budget(total, ranks, r);
        EXPECT_LE(b, total / static_cast<std::uint64_t>(ranks) + 1);
        sum += b;
      }
      EXPECT_EQ(sum, total) << total << " over " << ranks;
    }
}

}  // namespace
