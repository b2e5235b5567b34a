// PAR inside and outside a Runtime, its failures, and poison shutting down
// pipelines and rings.
#include <gtest/gtest.h>

#include <future>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "csp/csp.hpp"

namespace {

using namespace std::chrono_literals;

TEST(Par, WaitsForAllAndRethrowsAfterwards) {
  int finished = 0;
  bool caught = false;
  csp::Runtime rt(1);
  rt.spawn("parent", 0, [&] {
    try {
      csp::par({[&] { throw std::runtime_error("child failed"); },
                [&] {
                  csp::sleep_for(2ms);
                  ++finished;
                },
                [&] { ++finished; }});
    } catch (const std::runtime_error& e) {
      caught = std::string(e.what()) == "child failed";
      EXPECT_EQ(finished, 2);
    }
  });
  rt.run();
  EXPECT_TRUE(caught);
}

TEST(Par, SummarisesSeveralChildFailures) {
  csp::Runtime rt(1);
  std::string what;
  rt.spawn("parent", 0, [&] {
    try {
      csp::par({[] { throw std::runtime_error("x"); }, [] { throw std::runtime_error("y"); }});
    } catch (const csp::ProcessesFailed& e) {
      what = e.what();
    }
  });
  rt.run();
  EXPECT_NE(what.find("'parent.0' failed: x"), std::string::npos) << what;
  EXPECT_NE(what.find("'parent.1': y"), std::string::npos) << what;
}

TEST(Par, SeveralChildFailuresSayWhenMemoryRanOut) {
  csp::Runtime rt(1);
  std::optional<bool> out_of_memory;
  rt.spawn("parent", 0, [&] {
    try {
      csp::par({[] { throw std::bad_alloc(); }, [] { throw std::bad_alloc(); }});
    } catch (const csp::ProcessesFailed& e) {
      out_of_memory = e.out_of_memory();
    }
  });
  rt.run();
  EXPECT_EQ(out_of_memory, std::optional<bool>(true));
}

TEST(Par, WorksOutsideARuntime) {
  csp::Channel<int> c("c");
  int got = 0;
  csp::par({[out = c.writer()]() mutable { out.write(3); }, [&, in = c.reader()]() mutable { got = in.read(); }});
  EXPECT_EQ(got, 3);
}

// Outside a Runtime a PAR whose children deadlock throws Deadlock naming
// them, as inside one. Should it wait instead, its channels are poisoned
// after a while, so the test fails rather than hangs.
TEST(Par, ADeadlockOutsideARuntimeIsThrown) {
  csp::Channel<int> a("a");
  csp::Channel<int> b("b");
  std::promise<std::string> outcome;
  std::future<std::string> result = outcome.get_future();
  std::thread thread([&] {
    try {
      csp::par({[in = a.reader()]() mutable { in.read(); }, [in = b.reader()]() mutable { in.read(); }});
      outcome.set_value("returned");
    } catch (const csp::Deadlock& e) {
      outcome.set_value(e.what());
    } catch (const csp::Poisoned&) {
      outcome.set_value("waited");
    }
  });
  if (result.wait_for(10s) != std::future_status::ready) {
    a.poison();
    b.poison();
  }
  thread.join();
  const std::string what = result.get();
  EXPECT_EQ(what.rfind("deadlock: ", 0), 0u) << what;
  EXPECT_NE(what.find("process 'par.0' (thread 0): reading channel 'a'"), std::string::npos) << what;
  EXPECT_NE(what.find("process 'par.1' (thread 0): reading channel 'b'"), std::string::npos) << what;
}

// Each stage forwards values; on poison it poisons both its ends and ends.
void stage(csp::In<int> in, csp::Out<int> out) {
  try {
    for (;;) out.write(in.read() + 1);
  } catch (const csp::Poisoned&) {
    in.poison();
    out.poison();
  }
}

TEST(Poison, ShutsDownAPipeline) {
  constexpr int n = 6;
  std::vector<csp::Channel<int>> c;
  for (int i = 0; i <= n; ++i) c.emplace_back(std::to_string(i));  // "x" + to_string: a false GCC 12 -Wrestrict here
  std::vector<int> got;
  csp::Runtime rt(2);
  rt.spawn("source", 0, [out = c[0].writer()]() mutable {
    for (int i = 0; i < 10; ++i) out.write(i);
    out.poison();
  });
  for (int i = 0; i < n; ++i) {
    rt.spawn("stage" + std::to_string(i), i, [in = c[i].reader(), out = c[i + 1].writer()] { stage(in, out); });
  }
  rt.spawn("sink", 1, [in = c[n].reader(), &got]() mutable {
    for (;;) got.push_back(in.read());
  });
  rt.run();
  ASSERT_EQ(got.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(got[i], i + n);
  for (auto& ch : c) EXPECT_TRUE(ch.reader().poisoned());
}

TEST(Poison, ShutsDownARing) {
  constexpr int n = 8;
  std::vector<csp::Channel<int>> c;
  for (int i = 0; i < n; ++i) c.emplace_back("ring" + std::to_string(i));
  int laps = 0;
  csp::Runtime rt(2);
  rt.spawn("head", 0, [in = c[n - 1].reader(), out = c[0].writer(), &laps]() mutable {
    out.write(0);
    while (in.read() < 100 * n) {
      ++laps;
      out.write(laps * n);
    }
    out.poison();  // the others pass it round and end
  });
  for (int i = 1; i < n; ++i) {
    rt.spawn("node" + std::to_string(i), i, [in = c[i - 1].reader(), out = c[i].writer()]() mutable {
      try {
        for (;;) out.write(in.read() + 1);
      } catch (const csp::Poisoned&) {
        in.poison();
        out.poison();
      }
    });
  }
  rt.run();
  // The head's k-th write, k * n, comes back as k * n + n - 1 (n - 1 nodes add one each),
  // below 100 * n for k = 0 to 99: a lap counted each.
  EXPECT_EQ(laps, 100);
  for (auto& ch : c) EXPECT_TRUE(ch.reader().poisoned());
}

}  // namespace
