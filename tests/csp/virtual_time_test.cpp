// VirtualTimeScheduler: processes run in virtual-time order, receives complete
// at the later of sender and receiver, busy servers serialise, and the same
// program gives the same times on every run.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "csp/csp.hpp"
#include "csp/virtual_time.hpp"

namespace {

using csp::VirtualDuration;
using namespace std::chrono_literals;

csp::RuntimeOptions virtual_options(std::shared_ptr<csp::VirtualTimeRecord> record = {}) {
  csp::RuntimeOptions o;
  o.threads = 1;
  o.scheduler = csp::virtual_time_scheduler(std::move(record));
  return o;
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(csp::this_process::now()).count();
}

TEST(VirtualTime, ProcessesRunInOrderOfTheirClocks) {
  csp::Runtime rt(virtual_options());
  std::vector<std::pair<char, std::int64_t>> order;
  rt.spawn("slow", 0, [&] {
    csp::this_process::advance(5ns);
    order.emplace_back('s', now_ns());
  });
  rt.spawn("fast", 0, [&] {
    csp::this_process::advance(3ns);
    order.emplace_back('f', now_ns());
  });
  rt.run();
  EXPECT_EQ(order, (std::vector<std::pair<char, std::int64_t>>{{'f', 3}, {'s', 5}}));
}

// At equal times fibers run in the order they became ready: those that
// advanced to the time before those woken at it, and a sync() goes behind
// both.
TEST(VirtualTime, EqualTimesRunInTheOrderTheyBecameReady) {
  csp::Runtime rt(virtual_options());
  csp::Channel<int> wake("wake");
  std::vector<std::pair<std::string, std::int64_t>> order;
  rt.spawn("writer", 0, [&] {
    csp::this_process::advance(10ns);
    order.emplace_back("writer", now_ns());
    wake.writer().write(1);  // the reader becomes ready at 10, after "other"
    csp::this_process::sync();
    order.emplace_back("writer again", now_ns());
  });
  rt.spawn("reader", 0, [&] {
    wake.reader().read();
    order.emplace_back("reader", now_ns());
  });
  rt.spawn("other", 0, [&] {
    csp::this_process::advance(10ns);
    order.emplace_back("other", now_ns());
  });
  rt.run();
  EXPECT_EQ(order, (std::vector<std::pair<std::string, std::int64_t>>{
                       {"writer", 10}, {"other", 10}, {"reader", 10}, {"writer again", 10}}));
}

TEST(VirtualTime, ReceiveCompletesAtTheLaterOfSenderAndReceiver) {
  csp::Runtime rt(virtual_options());
  csp::Channel<int> early("early"), late("late");
  std::int64_t got_early = -1, got_late = -1;
  rt.spawn("writer", 0, [&] {
    csp::this_process::advance(10ns);
    late.writer().write(1);   // the reader waits from 0: it resumes at 10
    csp::this_process::advance(5ns);
    early.writer().write(2);  // sent at 15, read at 40
  });
  rt.spawn("reader", 0, [&] {
    late.reader().read();
    got_late = now_ns();
    csp::this_process::advance(30ns);
    early.reader().read();
    got_early = now_ns();
  });
  rt.run();
  EXPECT_EQ(got_late, 10);
  EXPECT_EQ(got_early, 40);
}

// A server that takes 4 ns per request: two requests sent at time 0 leave at
// 4 and 8, because the server is busy with one at a time.
TEST(VirtualTime, BusyServerSerialisesRequests) {
  auto record = std::make_shared<csp::VirtualTimeRecord>();
  csp::Runtime rt(virtual_options(record));
  csp::Channel<int> requests("requests", 2), replies("replies", 2);
  std::vector<std::int64_t> done;
  rt.spawn("server", 0, [&] {
    for (int i = 0; i < 2; ++i) {
      const int r = requests.reader().read();
      csp::this_process::delay(4ns);
      replies.writer().write(r);
    }
  });
  rt.spawn("client a", 0, [&] { requests.writer().write(1); });
  rt.spawn("client b", 0, [&] { requests.writer().write(2); });
  rt.spawn("sink", 0, [&] {
    for (int i = 0; i < 2; ++i) {
      replies.reader().read();
      done.push_back(now_ns());
    }
  });
  rt.run();
  EXPECT_EQ(done, (std::vector<std::int64_t>{4, 8}));
  EXPECT_EQ(record->end(), VirtualDuration(8000));
}

// Workers with pseudo-random compute times feed one merger through an ALT;
// the log of (worker, time) must be the same on every run.
struct Arrival {
  std::size_t worker;
  int sequence;
  std::int64_t time_ns;
  bool operator==(const Arrival&) const = default;
};

std::vector<Arrival> merge_log(std::uint32_t seed) {
  csp::Runtime rt(virtual_options());
  constexpr int workers = 4;
  std::vector<csp::Channel<int>> ch;
  for (int i = 0; i < workers; ++i) ch.emplace_back(std::string(1, char('a' + i)));
  std::vector<Arrival> log;
  for (int i = 0; i < workers; ++i) {
    rt.spawn("worker", 0, [&, i] {
      std::mt19937 rng(seed + static_cast<std::uint32_t>(i));
      for (int k = 0; k < 20; ++k) {
        csp::this_process::advance(std::chrono::nanoseconds(rng() % 7));
        ch[static_cast<std::size_t>(i)].writer().write(k);
      }
    });
  }
  rt.spawn("merger", 0, [&] {
    csp::Alt alt;
    for (auto& c : ch) alt.add_input(c.reader());
    for (int n = 0; n < workers * 20; ++n) {
      const std::size_t g = alt.select();
      const int k = ch[g].reader().read();
      log.push_back({g, k, now_ns()});
    }
  });
  rt.run();
  return log;
}

TEST(VirtualTime, SameProgramGivesSameTimesOnEveryRun) {
  const auto first = merge_log(7);
  ASSERT_EQ(first.size(), 80u);
  for (int run = 0; run < 3; ++run) EXPECT_EQ(merge_log(7), first);
}

TEST(VirtualTime, MergerSeesMessagesInTimeOrder) {
  const auto log = merge_log(11);
  std::int64_t last = 0;
  for (const Arrival& a : log) {
    EXPECT_GE(a.time_ns, last) << "worker " << a.worker << " message " << a.sequence;
    last = a.time_ns;
  }
}

TEST(VirtualTime, ClockIsZeroAndAdvanceIsNoOpOutsideVirtualTime) {
  csp::Runtime rt(1);
  bool inside = true;
  std::int64_t t = -1;
  rt.spawn("plain", 0, [&] {
    inside = csp::this_process::in_virtual_time();
    csp::this_process::advance(VirtualDuration(1000));
    t = now_ns();
  });
  rt.run();
  EXPECT_FALSE(inside);
  EXPECT_EQ(t, 0);
  EXPECT_FALSE(csp::this_process::in_virtual_time());
}

TEST(VirtualTime, NegativeAdvanceIsRejected) {
  csp::Runtime rt(virtual_options());
  bool threw = false;
  rt.spawn("p", 0, [&] {
    try {
      csp::this_process::advance(VirtualDuration(-1));
    } catch (const std::invalid_argument&) {
      threw = true;
    }
  });
  rt.run();
  EXPECT_TRUE(threw);
}

}  // namespace
