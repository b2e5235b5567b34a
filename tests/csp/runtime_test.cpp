// Runtime: creating and running processes on threads, failures and their
// summaries, stacks and their guard pages, what cannot start, blocking
// outside a Runtime, delivery across threads.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <fstream>
#include <future>
#include <new>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "csp/csp.hpp"
#include "csp/detail/stack.hpp"

namespace {

using namespace std::chrono_literals;

TEST(Runtime, CanBeCreatedAndDestroyedRepeatedly) {
  for (int round = 0; round < 5; ++round) {
    csp::Channel<int> c("c");
    int got = 0;
    csp::Runtime rt(2);
    EXPECT_EQ(rt.threads(), 2u);
    rt.spawn("writer", 0, [out = c.writer(), round]() mutable { out.write(round); });
    rt.spawn("reader", 1, [in = c.reader(), &got]() mutable { got = in.read(); });
    rt.run();
    EXPECT_EQ(got, round);
  }
}

TEST(Runtime, RunWithoutProcessesReturns) {
  csp::Runtime rt(2);
  rt.run();
  EXPECT_THROW(rt.run(), std::logic_error);
  EXPECT_THROW(rt.spawn("late", 0, [] {}), std::logic_error);
}

TEST(Runtime, SpawnAfterTheRunIsAnError) {
  csp::Runtime rt(1);
  rt.spawn("only", 0, [] {});
  rt.run();
  EXPECT_THROW(rt.spawn("late", 0, [] {}), std::logic_error);
}

TEST(Runtime, ProcessesKnowTheirNames) {
  std::string seen;
  std::string child;
  csp::Runtime rt(1);
  rt.spawn("worker", 0, [&] {
    seen = csp::current_process_name();
    csp::par({[&] { child = csp::current_process_name(); }});
  });
  rt.run();
  EXPECT_EQ(seen, "worker");
  EXPECT_EQ(child, "worker.0");
  EXPECT_EQ(csp::current_process_name(), "");
}

TEST(Runtime, SpawnFromInsideARunningProcess) {
  csp::Channel<int> c("c");
  int got = 0;
  csp::Runtime rt(2);
  rt.spawn("parent", 0, [&rt, &c, &got] {
    rt.spawn("child", 1, [out = c.writer()]() mutable { out.write(42); });
    got = c.reader().read();
  });
  rt.run();
  EXPECT_EQ(got, 42);
}

TEST(Runtime, RethrowsAProcessFailure) {
  csp::Runtime rt(2);
  rt.spawn("ok", 0, [] {});
  rt.spawn("bad", 1, [] { throw std::runtime_error("boom"); });
  EXPECT_THROW(
      try { rt.run(); } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "boom");
        throw;
      },
      std::runtime_error);
}

TEST(Runtime, SummarisesSeveralFailures) {
  csp::Runtime rt(1);
  rt.spawn("a", 0, [] { throw std::runtime_error("first"); });
  rt.spawn("b", 0, [] { throw std::runtime_error("second"); });
  try {
    rt.run();
    FAIL() << "run() did not throw";
  } catch (const csp::ProcessesFailed& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'a' failed: first"), std::string::npos) << what;
    EXPECT_NE(what.find("'b': second"), std::string::npos) << what;
    EXPECT_FALSE(e.out_of_memory());
  }
}

// Several failures of which one is std::bad_alloc say that memory ran out,
// so that a caller can add what to do about it.
TEST(Runtime, SeveralFailuresSayWhenMemoryRanOut) {
  csp::Runtime rt(1);
  rt.spawn("a", 0, [] { throw std::runtime_error("first"); });
  rt.spawn("b", 0, [] { throw std::bad_alloc(); });
  try {
    rt.run();
    FAIL() << "run() did not throw";
  } catch (const csp::ProcessesFailed& e) {
    EXPECT_TRUE(e.out_of_memory()) << e.what();
  }
}

// Runs use(c) for a fresh channel "c" of the given capacity on a thread of
// its own, outside any Runtime. Returns the message of the std::logic_error
// it threw, or "returned"; should it wait instead, c is poisoned after a
// while to free it and the result is "waited", so the test fails, not hangs.
// A refused wait must leave nothing behind: c then still carries a value.
std::string outside_any_runtime(std::size_t capacity, const std::function<void(csp::Channel<int>&)>& use) {
  csp::Channel<int> c("c", capacity);
  std::promise<std::string> outcome;
  std::future<std::string> result = outcome.get_future();
  std::thread thread([&] {
    try {
      use(c);
      outcome.set_value("returned");
    } catch (const std::logic_error& e) {
      outcome.set_value(e.what());
    } catch (const csp::Poisoned&) {
      outcome.set_value("waited");
    }
  });
  if (result.wait_for(10s) != std::future_status::ready) c.poison();
  thread.join();
  const std::string what = result.get();
  if (!c.reader().poisoned()) {
    int got = 0;
    csp::par({[out = c.writer()]() mutable { out.write(7); }, [&, in = c.reader()]() mutable { got = in.read(); }});
    EXPECT_EQ(got, 7) << "after: " << what;
  }
  return what;
}

// A plain thread is no process: a channel operation that would make it wait
// is an error naming the wait; one that need not wait works.
TEST(Runtime, AThreadOutsideAnyRuntimeThatWouldBlockGetsAnError) {
  const std::string refused = "a thread outside any csp::Runtime would block ";
  const std::string reading = refused + "reading channel 'c'; only processes and par() children may wait";
  EXPECT_EQ(outside_any_runtime(0, [](csp::Channel<int>& c) { c.reader().read(); }), reading);
  EXPECT_EQ(outside_any_runtime(0, [](csp::Channel<int>& c) { c.reader().read_for(1h); }), reading);
  EXPECT_EQ(outside_any_runtime(0, [](csp::Channel<int>& c) { c.writer().write(1); }),
            refused + "writing channel 'c'; only processes and par() children may wait");
  for (csp::Alt::Waiting waiting : {csp::Alt::Waiting::relink, csp::Alt::Waiting::doorbell}) {
    for (bool timeout : {false, true}) {
      EXPECT_EQ(outside_any_runtime(0,
                                    [&](csp::Channel<int>& c) {
                                      csp::Alt alt(waiting);
                                      alt.add_input(c.reader());
                                      if (timeout) alt.add_timeout(1h);
                                      alt.select();
                                    }),
                refused + "in ALT over channels 'c'; only processes and par() children may wait")
          << "doorbell " << (waiting == csp::Alt::Waiting::doorbell) << ", timeout " << timeout;
    }
    // A timeout alone (which poisoning c cannot end, hence a short one).
    EXPECT_EQ(outside_any_runtime(0,
                                  [&](csp::Channel<int>&) {
                                    csp::Alt alt(waiting);
                                    alt.add_timeout(15s);
                                    alt.select();
                                  }),
              refused + "in ALT over no channel; only processes and par() children may wait")
        << "doorbell " << (waiting == csp::Alt::Waiting::doorbell);
  }
  // Buffered: the write finds room and the first read a value; the second
  // read would wait.
  EXPECT_EQ(outside_any_runtime(1,
                                [](csp::Channel<int>& c) {
                                  c.writer().write(1);
                                  EXPECT_EQ(c.reader().read(), 1);
                                  c.reader().read();
                                }),
            reading);
}

// The mapping of this process's memory that holds `address`, from
// /proc/self/maps: its first address and permissions ("rw-p", "---p", ...).
struct Mapping {
  std::uintptr_t start = 0;
  std::string permissions;
};
std::optional<Mapping> mapping_of(std::uintptr_t address) {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    std::istringstream fields(line);
    std::string range, permissions;
    fields >> range >> permissions;
    const std::size_t dash = range.find('-');
    const std::uintptr_t start = std::stoull(range.substr(0, dash), nullptr, 16);
    const std::uintptr_t end = std::stoull(range.substr(dash + 1), nullptr, 16);
    if (address >= start && address < end) return Mapping{start, permissions};
  }
  return std::nullopt;
}

// Below a process's stack lies a page nobody may touch, so a process that
// runs off the end of its stack faults there rather than writing over
// memory that is not its own.
TEST(Runtime, AProcessStackHasAGuardPageBelowIt) {
  std::optional<Mapping> stack, below;
  csp::Runtime rt(1);
  rt.spawn("p", 0, [&] {
    volatile char local = 0;
    stack = mapping_of(reinterpret_cast<std::uintptr_t>(&local));
    if (stack) below = mapping_of(stack->start - 1);
  });
  rt.run();
  ASSERT_TRUE(stack);
  EXPECT_EQ(stack->permissions.substr(0, 3), "rw-");
  ASSERT_TRUE(below) << "nothing is mapped below the stack";
  EXPECT_EQ(below->permissions.substr(0, 3), "---") << "the page below a process's stack is accessible";
}

// Guarded stacks take two of the process's memory mappings each, so past a
// quarter of the kernel's limit processes get unguarded stacks, and a run
// with more processes than the guarded ones could number still runs.
TEST(Runtime, MoreProcessesThanGuardedStacksCouldNumberAllRun) {
#if defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "ThreadSanitizer maps shadow memory beside every stack, so the kernel's limit on mappings "
                  "comes before the runtime's";
#endif
  const std::size_t limit = csp::detail::ProcessStack::guarded_limit();
  const std::size_t processes = 2 * limit + 1000;
  csp::RuntimeOptions options;
  options.threads = 1;
  options.stack_size = 16 * 1024;
  csp::Runtime rt(options);
  std::size_t ran = 0, most_guarded = 0;
  for (std::size_t i = 0; i < processes; ++i)
    rt.spawn("p", 0, [&] {
      ++ran;
      most_guarded = std::max(most_guarded, csp::detail::ProcessStack::guarded_alive());
      csp::sleep_for(1ms);  // so that every stack is alive at once
    });
  rt.run();
  EXPECT_EQ(ran, processes);
  EXPECT_EQ(most_guarded, limit);
  EXPECT_EQ(csp::detail::ProcessStack::guarded_alive(), limit) << "ended processes' guarded stacks are kept";
}

// A process whose stack cannot be mapped (here none can: 128 TB is more than
// the whole user address space) is reported by run(), which names it and
// counts the others, instead of ending the program.
TEST(Runtime, AProcessThatCannotStartIsReportedByRun) {
  csp::RuntimeOptions options;
  options.threads = 2;
  options.stack_size = std::size_t{1} << 47;
  csp::Runtime rt(options);
  std::atomic<int> ran{0};
  for (const char* name : {"first", "second", "third"}) rt.spawn(name, 0, [&] { ++ran; });
  try {
    rt.run();
    FAIL() << "run() returned";
  } catch (const csp::ProcessNotStarted& e) {
    EXPECT_EQ(std::string(e.what()),
              "process 'first' could not start: no memory for a 137438953472 KB process stack: Cannot allocate memory "
              "(and 2 more processes)");
  }
  EXPECT_EQ(ran, 0);
}

// The address space this process may map, lowered for one test and then
// restored.
class AddressSpaceLimit {
 public:
  explicit AddressSpaceLimit(rlim_t bytes) {
    getrlimit(RLIMIT_AS, &saved_);
    rlimit lowered = saved_;
    lowered.rlim_cur = bytes;
    setrlimit(RLIMIT_AS, &lowered);
  }
  ~AddressSpaceLimit() { setrlimit(RLIMIT_AS, &saved_); }

 private:
  rlimit saved_{};
};

std::size_t mapped_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

// A runtime thread the system cannot create (no room for its stack) makes
// run() throw before any process starts, rather than end the program with
// the threads it did create still running. Of 64 threads, at most the few
// whose stacks the C library keeps for reuse can start within 4 MB more.
TEST(Runtime, AThreadThatCannotBeCreatedAbandonsTheRunBeforeAnyProcess) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory cannot run under a lowered address-space limit";
#endif
  csp::Runtime rt(64);
  std::atomic<int> ran{0};
  for (unsigned t = 0; t < 64; ++t) rt.spawn("p", t, [&] { ++ran; });
  std::string error;
  {
    const AddressSpaceLimit limit(mapped_bytes() + 4 * 1024 * 1024);
    try {
      rt.run();
    } catch (const csp::ThreadNotStarted& e) {
      error = e.what();
    }
  }
  EXPECT_EQ(error.rfind("csp: could not start runtime thread ", 0), 0u) << error;
  EXPECT_NE(error.find(" of 64, so no process ran: "), std::string::npos) << error;
  EXPECT_EQ(ran, 0);
}

// A runtime thread that cannot set up its scheduler (here its factory
// fails, as allocating it would with no memory left) abandons the run
// before any process starts, rather than ending the program.
TEST(Runtime, AThreadThatCannotSetUpAbandonsTheRunBeforeAnyProcess) {
  csp::RuntimeOptions options;
  options.threads = 4;
  options.scheduler = [](unsigned thread) -> csp::Scheduler* {
    if (thread == 2) throw std::bad_alloc();
    return new csp::FifoScheduler();
  };
  csp::Runtime rt(options);
  std::atomic<int> ran{0};
  for (unsigned t = 0; t < 4; ++t) rt.spawn("p", t, [&] { ++ran; });
  try {
    rt.run();
    FAIL() << "run() did not throw";
  } catch (const csp::ThreadNotStarted& e) {
    EXPECT_STREQ(e.what(), "csp: could not set up runtime thread 3 of 4, so no process ran: std::bad_alloc");
  }
  EXPECT_EQ(ran, 0);
}

// Processes left waiting on one that failed deadlock; run() reports the
// failure, which caused it, rather than the deadlock.
TEST(Runtime, ReportsAFailureRatherThanTheDeadlockItLeftBehind) {
  csp::Channel<int> c("c");
  csp::Runtime rt(2);
  rt.spawn("writer", 0, [] { throw std::runtime_error("no value to send"); });
  rt.spawn("reader", 1, [in = c.reader()]() mutable { in.read(); });
  try {
    rt.run();
    FAIL() << "run() did not throw";
  } catch (const csp::Deadlock& e) {
    FAIL() << "reported the deadlock: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "no value to send");
  }
}

TEST(Runtime, NamesTheFirstFewOfManyFailures) {
  csp::Runtime rt(1);
  for (char digit = '0'; digit <= '9'; ++digit) {
    const std::string error{'e', digit};
    rt.spawn(std::string{'p', digit}, 0, [error] { throw std::runtime_error(error); });
  }
  try {
    rt.run();
    FAIL() << "run() did not throw";
  } catch (const csp::ProcessesFailed& e) {
    EXPECT_STREQ(e.what(), "process 'p0' failed: e0; and 9 more: process 'p1': e1; process 'p2': e2; "
                           "process 'p3': e3; ...");
  }
}

TEST(Runtime, CrossThreadStressDeliversEverything) {
  constexpr int producers = 16;
  constexpr int per_producer = 5000;
  csp::Channel<std::uint64_t> sink("sink");
  std::vector<csp::Channel<std::uint64_t>> mid;
  for (int i = 0; i < producers; ++i) mid.emplace_back("mid" + std::to_string(i), i % 3);
  std::uint64_t sum = 0;
  std::uint64_t count = 0;
  csp::Runtime rt(2);
  for (int i = 0; i < producers; ++i) {
    rt.spawn("producer" + std::to_string(i), i, [out = mid[i].writer(), i]() mutable {
      for (int k = 0; k < per_producer; ++k) out.write(static_cast<std::uint64_t>(i) * per_producer + k);
    });
    rt.spawn("relay" + std::to_string(i), i + 1, [in = mid[i].reader(), out = sink.writer()]() mutable {
      for (int k = 0; k < per_producer; ++k) out.write(in.read());
    });
  }
  rt.spawn("consumer", 0, [in = sink.reader(), &sum, &count]() mutable {
    for (int k = 0; k < producers * per_producer; ++k) {
      sum += in.read();
      ++count;
    }
  });
  rt.run();
  const std::uint64_t n = std::uint64_t{producers} * per_producer;
  EXPECT_EQ(count, n);
  EXPECT_EQ(sum, n * (n - 1) / 2);
}

// More runtime threads than hardware threads: idle threads go straight to
// sleep, and every wake across threads must still reach them.
TEST(Runtime, MoreThreadsThanTheMachineDeliverEverything) {
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency()) + 2;
  constexpr int stages = 12;
  constexpr int messages = 2000;
  std::vector<csp::Channel<int>> links;
  for (int i = 0; i <= stages; ++i) links.emplace_back("link" + std::to_string(i));
  csp::Runtime rt(threads);
  rt.spawn("source", 0, [out = links[0].writer()]() mutable {
    for (int k = 0; k < messages; ++k) out.write(k);
  });
  for (int i = 0; i < stages; ++i)
    rt.spawn("stage" + std::to_string(i), static_cast<unsigned>(i + 1),
             [in = links[i].reader(), out = links[i + 1].writer()]() mutable {
               for (int k = 0; k < messages; ++k) out.write(in.read() + 1);
             });
  std::int64_t sum = 0;
  int count = 0;
  rt.spawn("sink", static_cast<unsigned>(stages + 1), [in = links[stages].reader(), &sum, &count]() mutable {
    for (int k = 0; k < messages; ++k) {
      sum += in.read();
      ++count;
    }
  });
  rt.run();
  EXPECT_EQ(rt.threads(), threads);
  EXPECT_EQ(count, messages);
  EXPECT_EQ(sum, std::int64_t{messages} * (messages - 1) / 2 + std::int64_t{messages} * stages);
}

}  // namespace
