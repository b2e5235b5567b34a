// The deadlock detector: a deadlock is found and every process in it named,
// through channels, ALTs and PARs; waiting threads while another runs, and
// timers, are not deadlocks.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "csp/csp.hpp"

namespace {

using namespace std::chrono_literals;

TEST(Deadlock, DetectedInARingNamingEveryProcess) {
  constexpr int n = 4;
  std::vector<csp::Channel<int>> c;
  for (int i = 0; i < n; ++i) c.emplace_back("link" + std::to_string(i));
  std::atomic<int> unwound{0};
  struct Count {
    std::atomic<int>& n;
    ~Count() { ++n; }
  };
  csp::Runtime rt(2);
  for (int i = 0; i < n; ++i) {
    // Everyone reads first: nobody ever writes.
    rt.spawn("node" + std::to_string(i), i, [in = c[i].reader(), out = c[(i + 1) % n].writer(), &unwound]() mutable {
      Count guard{unwound};
      out.write(in.read());
    });
  }
  try {
    rt.run();
    FAIL() << "no deadlock reported";
  } catch (const csp::Deadlock& e) {
    const std::string what = e.what();
    for (int i = 0; i < n; ++i) {
      EXPECT_NE(what.find("'node" + std::to_string(i) + "'"), std::string::npos) << what;
      EXPECT_NE(what.find("reading channel 'link" + std::to_string(i) + "'"), std::string::npos) << what;
    }
  }
  EXPECT_EQ(unwound.load(), n);
}

// Four threads; on threads 1-3 a process ("waiter") waits on a channel of
// its own, while on thread 0 "ping" sends `exchanges` values to "pong".
// ping then writes every waiter's channel if `release`, or both end by
// reading channels nobody writes. Should the run hang, a watchdog poisons
// every channel after a while, so the test fails rather than hangs.
struct ThreadsThatWaitWhileOneRuns {
  static constexpr unsigned threads = 4;
  static constexpr int exchanges = 20000;
  std::vector<csp::Channel<int>> waiting;  // one per waiter, then ping's, then pong's
  csp::Channel<int> exchange{"exchange"};
  std::vector<int> got = std::vector<int>(threads, 0);

  ThreadsThatWaitWhileOneRuns() {
    for (unsigned t = 0; t <= threads; ++t) waiting.emplace_back("waiting" + std::to_string(t));
  }

  // Returns the Deadlock's message, "ended" or "hung".
  std::string run(bool release) {
    csp::Runtime rt(threads);
    for (unsigned t = 1; t < threads; ++t)
      rt.spawn("waiter" + std::to_string(t), t, [this, t] { got[t] = waiting[t].reader().read(); });
    rt.spawn("ping", 0, [this, release] {
      for (int i = 0; i < exchanges; ++i) exchange.writer().write(i);
      if (!release) waiting[0].reader().read();
      for (unsigned t = 1; t < threads; ++t) waiting[t].writer().write(static_cast<int>(t));
    });
    rt.spawn("pong", 0, [this, release] {
      for (int i = 0; i < exchanges; ++i) EXPECT_EQ(exchange.reader().read(), i);
      if (!release) waiting[threads].reader().read();
    });
    std::promise<void> done;
    std::thread watchdog([this, ended = done.get_future()] {
      if (ended.wait_for(20s) == std::future_status::ready) return;
      for (auto& c : waiting) c.poison();
    });
    std::string outcome = "ended";
    try {
      rt.run();
      if (waiting[0].reader().poisoned()) outcome = "hung";
    } catch (const csp::Deadlock& e) {
      outcome = e.what();
    } catch (const csp::Poisoned&) {
      outcome = "hung";
    }
    done.set_value();
    watchdog.join();
    return outcome;
  }
};

// The runtime counts blocked processes per thread: a thread whose every
// process waits is no deadlock while a process of another thread can run.
TEST(Deadlock, ThreadsWhoseProcessesAllWaitAreNoDeadlockWhileAnotherRuns) {
  ThreadsThatWaitWhileOneRuns run;
  EXPECT_EQ(run.run(true), "ended");
  for (unsigned t = 1; t < run.threads; ++t) EXPECT_EQ(run.got[t], static_cast<int>(t));
}

// ... and the last thread whose processes all come to wait sees the others'.
TEST(Deadlock, DetectedWhenTheLastThreadToRunComesToWait) {
  ThreadsThatWaitWhileOneRuns run;
  const std::string what = run.run(false);
  ASSERT_NE(what, "ended");
  ASSERT_NE(what, "hung");
  for (const char* name : {"'waiter1' (thread 1)", "'waiter3' (thread 3)", "'ping' (thread 0)", "'pong' (thread 0)"})
    EXPECT_NE(what.find(name), std::string::npos) << what;
}

TEST(Deadlock, DetectedThroughAltAndPar) {
  csp::Channel<int> a("a");
  csp::Channel<int> b("b");
  csp::Runtime rt(1);
  rt.spawn("parent", 0, [&] {
    csp::par({[in = a.reader()]() mutable { in.read(); },
              [&] {
                csp::Alt alt;
                alt.add_input(b.reader());
                alt.add_input(a.reader());
                alt.select();
              }});
  });
  try {
    rt.run();
    FAIL() << "no deadlock reported";
  } catch (const csp::Deadlock& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'parent' (thread 0): in PAR"), std::string::npos) << what;
    EXPECT_NE(what.find("'parent.0' (thread 0): reading channel 'a'"), std::string::npos) << what;
    EXPECT_NE(what.find("'parent.1' (thread 0): in ALT over channels"), std::string::npos) << what;
  }
}

TEST(Deadlock, DetectedThroughDoorbellAlt) {
  csp::Channel<int> a("a", 1);
  csp::Channel<int> b("b");
  csp::Channel<int> c("c");
  bool unwound = false;
  csp::Runtime rt(2);
  rt.spawn("alt", 1, [&] {
    struct Unwound {
      bool& flag;
      ~Unwound() { flag = true; }
    } guard{unwound};
    csp::Alt alt(csp::Alt::Waiting::doorbell);
    alt.add_input(a.reader());
    alt.add_input(b.reader());
    alt.select();
  });
  rt.spawn("reader", 0, [in = c.reader()]() mutable { in.read(); });
  try {
    rt.run();
    FAIL() << "no deadlock reported";
  } catch (const csp::Deadlock& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'alt' (thread 1): in ALT over channels"), std::string::npos) << what;
    EXPECT_NE(what.find("'a'"), std::string::npos) << what;
  }
  EXPECT_TRUE(unwound);
}

TEST(Deadlock, TimersAreNotMistakenForDeadlock) {
  csp::Channel<int> c("c");
  csp::Channel<int> d("d");
  int got = 0;
  csp::Runtime rt(2);
  rt.spawn("reader", 0, [in = c.reader(), &got]() mutable { got = in.read(); });
  rt.spawn("sleeper", 1, [out = c.writer()]() mutable {
    csp::sleep_for(5ms);
    out.write(1);
  });
  rt.spawn("waiter", 1, [in = d.reader()]() mutable { EXPECT_FALSE(in.read_for(3ms)); });
  rt.spawn("alt", 0, [in = d.reader()]() mutable {
    csp::Alt alt;
    alt.add_input(in);
    alt.add_timeout(3ms);
    EXPECT_EQ(alt.select(), 1u);
  });
  rt.run();
  EXPECT_EQ(got, 1);
}

}  // namespace
