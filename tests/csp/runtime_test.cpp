// Runtime and PAR: placement, failures, poison shutdown, deadlock diagnosis,
// blocking outside a Runtime.
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
  for (int i = 0; i <= n; ++i) c.emplace_back("c" + std::to_string(i));
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
  EXPECT_GT(laps, 0);
  for (auto& ch : c) EXPECT_TRUE(ch.reader().poisoned());
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

// One thread, so the order of the log is the scheduler's. Each low-priority
// process yields first: a process's first run, at spawn, is not yet sorted
// by its priority.
TEST(Priority, AReadyHighPriorityProcessRunsBeforeQueuedLowPriorityOnes) {
  csp::Channel<int> c("c", 1);
  std::vector<std::string> log;
  csp::Runtime rt(1);
  rt.spawn("high", 0, [in = c.reader(), &log]() mutable {
    log.push_back("high waits");
    in.read();
    log.push_back("high got");
  });
  rt.spawn(
      "low 1", 0,
      [out = c.writer(), &log]() mutable {
        csp::yield();
        out.write(1);
        log.push_back("low 1 wrote");
        csp::yield();
        log.push_back("low 1 again");
      },
      csp::Priority::low);
  rt.spawn(
      "low 2", 0,
      [&log] {
        csp::yield();
        log.push_back("low 2");
      },
      csp::Priority::low);
  rt.run();
  // In plain FIFO order "low 2" would come before "high got".
  EXPECT_EQ(log, (std::vector<std::string>{"high waits", "low 1 wrote", "high got", "low 2", "low 1 again"}));
}

// One thread. The writer hands its message over and yields; the reader it
// woke then runs before the yielder, which gave the thread up earlier.
TEST(Priority, AWokenLowPriorityProcessRunsBeforeOnesThatYielded) {
  csp::Channel<int> c("c");
  std::vector<std::string> log;
  csp::Runtime rt(1);
  rt.spawn(
      "reader", 0,
      [in = c.reader(), &log]() mutable {
        csp::yield();
        log.push_back("reader waits");
        in.read();
        log.push_back("reader got");
      },
      csp::Priority::low);
  rt.spawn(
      "yielder", 0,
      [&log] {
        for (int i = 1; i <= 3; ++i) {
          csp::yield();
          log.push_back("yielder " + std::to_string(i));
        }
      },
      csp::Priority::low);
  rt.spawn(
      "writer", 0,
      [out = c.writer(), &log]() mutable {
        csp::yield();
        csp::yield();
        out.write(1);
        log.push_back("writer wrote");
        csp::yield();
        log.push_back("writer again");
      },
      csp::Priority::low);
  rt.run();
  // In plain FIFO order "yielder 3" would come before "reader got".
  EXPECT_EQ(log, (std::vector<std::string>{"reader waits", "yielder 1", "yielder 2", "writer wrote", "reader got",
                                           "yielder 3", "writer again"}));
}

TEST(Priority, ParChildrenRunAtTheirParentsPriority) {
  csp::Channel<int> c("c", 1);
  std::vector<std::string> log;
  csp::Runtime rt(1);
  rt.spawn("high", 0, [in = c.reader(), &log]() mutable {
    in.read();
    log.push_back("high got");
  });
  rt.spawn(
      "low", 0,
      [out = c.writer(), &log]() mutable {
        csp::par({[&] {
                    csp::yield();
                    out.write(1);
                    log.push_back("a wrote");
                    csp::yield();
                    log.push_back("a again");
                  },
                  [&] {
                    csp::yield();
                    log.push_back("b");
                  }});
      },
      csp::Priority::low);
  rt.run();
  // Children at high priority would queue "b" ahead of the reader.
  EXPECT_EQ(log, (std::vector<std::string>{"a wrote", "high got", "b", "a again"}));
}

TEST(Priority, LowPriorityProcessesOnTwoThreadsDeliverEverything) {
  constexpr int count = 2000;
  csp::Channel<int> c("c", 4);
  long sum = 0;
  csp::Runtime rt(2);
  rt.spawn(
      "producer", 0,
      [out = c.writer()]() mutable {
        for (int i = 1; i <= count; ++i) {
          out.write(i);
          if (i % 7 == 0) csp::yield();
        }
      },
      csp::Priority::low);
  rt.spawn(
      "consumer", 1,
      [in = c.reader(), &sum]() mutable {
        for (int i = 0; i < count; ++i) sum += in.read();
      },
      csp::Priority::low);
  rt.spawn("busy high", 1, [] {
    for (int i = 0; i < 100; ++i) csp::yield();
  });
  rt.run();
  EXPECT_EQ(sum, long{count} * (count + 1) / 2);
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
// so they add up to its wall time; thread 0 computes for 30 ms, which shows
// as running time, while thread 1 waits for it, first spinning, then asleep.
TEST(Runtime, ThreadUseSplitAddsUpToWallTime) {
  using Clock = std::chrono::steady_clock;
  csp::Channel<int> started("started");
  csp::Channel<int> done("done");
  csp::Runtime rt(2);
  rt.spawn("busy", 0, [in = started.reader(), out = done.writer()]() mutable {
    in.read();
    const auto until = Clock::now() + 30ms;
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
  EXPECT_GE(use[0].running_seconds, 0.03);
  EXPECT_GE(use[1].waits, 1u);
  // Thread 1 waits 30 ms at least, far past any spin, so it sleeps.
  EXPECT_GE(use[1].sleeps, 1u);
  EXPECT_GE(use[1].spinning_seconds + use[1].sleeping_seconds, 0.025);
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

// yield_requested(): a long low-priority computation that asks between
// steps lets through a process woken from another thread at the next step.
// "busy" stops only once "reader" has every value, which it can have only
// if busy yields when told (with no rule, busy would run to its bound);
// each write comes from thread 0 while thread 1 runs busy, so none of
// those wakes finds thread 1 asleep.
TEST(Runtime, YieldRequestedLetsAProcessWokenFromAnotherThreadThrough) {
  using Clock = std::chrono::steady_clock;
  constexpr int values = 200;
  csp::Channel<int> c("c");
  std::atomic<int> received{0};
  std::atomic<bool> bounded{false};
  long steps = 0, yields = 0;
  csp::Runtime rt(2);
  rt.spawn("writer", 0, [out = c.writer()]() mutable {
    for (int i = 0; i < values; ++i) out.write(i);
  });
  rt.spawn("reader", 1, [in = c.reader(), &received]() mutable {
    for (int i = 0; i < values; ++i) {
      EXPECT_EQ(in.read(), i);
      received.store(i + 1, std::memory_order_relaxed);
    }
  });
  rt.spawn(
      "busy", 1,
      [&] {
        const auto bound = Clock::now() + 20s;
        while (received.load(std::memory_order_relaxed) < values) {
          if (Clock::now() > bound) {
            bounded = true;
            return;
          }
          ++steps;
          if (csp::yield_requested()) {
            ++yields;
            csp::yield();
          }
        }
      },
      csp::Priority::low);
  rt.run();
  EXPECT_FALSE(bounded) << "the reader got " << received.load() << " of " << values;
  EXPECT_EQ(received.load(), values);
  EXPECT_GE(yields, 1);
  EXPECT_GE(steps, yields);
  const auto use = rt.thread_use();
  EXPECT_GE(use[0].remote_wakes, 1u);
  // At most the wake that ends the run may find thread 1 asleep: one from
  // thread 0 if its writer happens to be the last process to end.
  EXPECT_LE(use[0].sleepers_woken, 1u);
}

// Nothing else ready, nothing arrived: no yield is requested; outside a
// Runtime never.
TEST(Runtime, YieldRequestedIsFalseWithNothingWaiting) {
  EXPECT_FALSE(csp::yield_requested());
  bool asked = true;
  csp::Runtime rt(1);
  rt.spawn("alone", 0, [&asked] { asked = csp::yield_requested(); }, csp::Priority::low);
  rt.run();
  EXPECT_FALSE(asked);
}

// A ready high-priority process is a request too, and yielding to it keeps
// the priority order: it runs before the low-priority caller resumes.
TEST(Runtime, YieldRequestedByAReadyHighPriorityProcess) {
  std::vector<std::string> order;
  csp::Channel<int> go("go", 1);
  csp::Runtime rt(1);
  rt.spawn(
      "low", 0,
      [&order, out = go.writer()]() mutable {
        out.write(1);  // buffered: wakes "high", which is now ready
        const bool asked = csp::yield_requested();
        order.push_back(asked ? "low asked" : "low not asked");
        if (asked) csp::yield();
        order.push_back("low resumed");
      },
      csp::Priority::low);
  rt.spawn("high", 0, [&order, in = go.reader()]() mutable {
    in.read();
    order.push_back("high");
  });
  rt.run();
  EXPECT_EQ(order, (std::vector<std::string>{"low asked", "high", "low resumed"}));
}

// A stream of wakes from another thread does not starve a low-priority
// process that yields whenever asked: each woken process runs until it
// waits again, then the computation goes on. It goes on until it has taken
// its steps and the reader, on its thread, has had 100 values (the wakes
// it yielded to), and the run ends in order when it is done (the sender
// then poisons the channel, ending the reader).
TEST(Runtime, YieldOnRequestDoesNotStarveTheLowPriorityProcess) {
  using Clock = std::chrono::steady_clock;
  constexpr long steps = 20000, wanted_reads = 100;
  csp::Channel<int> c("c");
  std::atomic<bool> done{false};
  bool bounded = false;
  long reads = 0, taken = 0;  // both written on thread 1 only
  csp::Runtime rt(2);
  rt.spawn("sender", 0, [out = c.writer(), &done]() mutable {
    while (!done.load(std::memory_order_relaxed)) out.write(1);
    out.poison();
  });
  rt.spawn("reader", 1, [in = c.reader(), &reads]() mutable {
    try {
      for (;;) reads += in.read();
    } catch (const csp::Poisoned&) {
    }
  });
  rt.spawn(
      "computer", 1,
      [&] {
        const auto bound = Clock::now() + 20s;
        for (; taken < steps || reads < wanted_reads; ++taken) {
          if (Clock::now() > bound) {
            bounded = true;
            break;
          }
          if (csp::yield_requested()) csp::yield();
        }
        done = true;
      },
      csp::Priority::low);
  rt.run();
  EXPECT_FALSE(bounded) << "reads " << reads << ", steps " << taken;
  EXPECT_GE(taken, steps);
  EXPECT_GE(reads, wanted_reads);
}

// A process woken from another thread runs within a few switches of its
// thread, even while that thread is never idle: the wake is dispatched at
// the next switch, not after a round of the ready queue. A busy process on
// thread 1 counts its yields; the reader there notes how many passed between
// the writer's message on thread 0 and its own resumption. Each busy turn
// lasts 2 us, longer than the writer's path from noting the count to the
// wake, so that path adds about one switch however slow the build (TSan)
// makes it, while a dispatch every 32 picks would still add about 12.
TEST(Runtime, AWakeFromAnotherThreadIsDispatchedAtTheNextSwitch) {
  constexpr int trials = 200;
  csp::Channel<int> c("c");
  std::atomic<long> switches{0}, at_write{0};
  std::atomic<bool> stop{false};
  std::vector<long> delays;
  csp::Runtime rt(2);
  for (const char* name : {"busy 1", "busy 2"})  // one of them is always ready
    rt.spawn(
        name, 1,
        [&] {
          while (!stop.load(std::memory_order_relaxed)) {
            const auto until = std::chrono::steady_clock::now() + 2us;
            while (std::chrono::steady_clock::now() < until) {
            }
            switches.fetch_add(1, std::memory_order_relaxed);
            csp::yield();
          }
        },
        csp::Priority::low);
  rt.spawn("reader", 1, [in = c.reader(), &switches, &at_write, &delays]() mutable {
    for (int i = 0; i < trials; ++i) {
      in.read();
      delays.push_back(switches.load(std::memory_order_relaxed) - at_write.load(std::memory_order_relaxed));
    }
  });
  rt.spawn("writer", 0, [out = c.writer(), &switches, &at_write, &stop]() mutable {
    for (int i = 0; i < trials; ++i) {
      const auto until = std::chrono::steady_clock::now() + 20us;  // let the reader park
      while (std::chrono::steady_clock::now() < until) {
      }
      at_write.store(switches.load(std::memory_order_relaxed), std::memory_order_relaxed);
      out.write(i);
    }
    stop.store(true, std::memory_order_relaxed);
  });
  rt.run();
  ASSERT_EQ(delays.size(), std::size_t{trials});
  std::sort(delays.begin(), delays.end());
  // The median is 1 here; left to a dispatch every 32 picks it is 12-13.
  EXPECT_LE(delays[trials / 2], 8) << "90th percentile " << delays[trials * 9 / 10] << ", most " << delays.back();
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
