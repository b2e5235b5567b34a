// Support for tests that run one case under many seeds: the range of seeds
// to run, the line that tells how to replay a failing one, a watchdog that
// turns a hang into a failure, and seeded pauses for the processes at the
// ends of what is tested.
// Invariants: the seeds follow the convention of
// tests/nodes/machine/seeded_schedule_test.cpp: VMPRAY_SCHEDULE_SEEDS=N runs
// N seeds per case (each test has its own default, a quarter of it in a
// sanitizer build), from VMPRAY_SCHEDULE_FIRST_SEED (default 0), and
// FIRST_SEED=S with SEEDS=1 replays seed S alone. A Watchdog past its limit
// calls its stop function once (which must be safe from any thread, as
// poisoning a channel is) and reports that it fired; if the run still has
// not ended after a second limit, it prints the case and its replay line
// and aborts, so a hang can never stall the suite. A Pacer draws its
// pauses from a sequence of its own, so a process pauses alike in every
// run of a seed.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <utility>

#include "csp/runtime.hpp"
#include "csp/scheduler.hpp"

namespace test {

struct SeedRange {
  std::uint64_t first = 0;
  std::uint64_t count = 0;
};

inline std::uint64_t seed_setting(const char* name, std::uint64_t fallback) {
  const char* text = std::getenv(name);
  return text && *text ? std::strtoull(text, nullptr, 10) : fallback;
}

// The seeds to run: `default_count` of them (a quarter under a sanitizer,
// which runs threads several times slower) unless the environment says
// otherwise.
inline SeedRange seed_range(std::uint64_t default_count) {
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
  default_count = (default_count + 3) / 4;
#endif
  return {seed_setting("VMPRAY_SCHEDULE_FIRST_SEED", 0), seed_setting("VMPRAY_SCHEDULE_SEEDS", default_count)};
}

// "seed 17 (replay: VMPRAY_SCHEDULE_FIRST_SEED=17 VMPRAY_SCHEDULE_SEEDS=1
// net_tests --gtest_filter=ThreadRelays.Foo)" for the running test of the
// test program `program`.
inline std::string replay_line(std::uint64_t seed, const std::string& program) {
  const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
  const std::string filter = test ? std::string(test->test_suite_name()) + "." + test->name() : "*";
  return "seed " + std::to_string(seed) + " (replay: VMPRAY_SCHEDULE_FIRST_SEED=" + std::to_string(seed) +
         " VMPRAY_SCHEDULE_SEEDS=1 " + program + " --gtest_filter=" + filter + ")";
}

// Bounds the wall time of one run: past `limit`, stop() once; past twice
// the limit, abort with `what` (the case and its replay line). Given
// `progress` (a count the run raises as it works, read from the watchdog's
// thread), the limit bounds the time the run goes without the count
// changing instead, and ten limits its whole time: a run the OS slows down
// (a loaded machine, a sanitizer) is not taken for a hung one, while a hung
// one, or one that works on without end, is still stopped.
class Watchdog {
 public:
  Watchdog(std::chrono::milliseconds limit, std::function<void()> stop, std::string what,
           std::function<std::uint64_t()> progress = nullptr)
      : limit_(limit),
        stop_(std::move(stop)),
        what_(std::move(what)),
        progress_(std::move(progress)),
        thread_([this] { watch(); }) {}
  ~Watchdog() {
    {
      std::lock_guard<std::mutex> lk(mutex_);
      done_ = true;
    }
    woken_.notify_all();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  // True if the run outlived its limit and was stopped.
  bool fired() const {
    std::lock_guard<std::mutex> lk(mutex_);
    return fired_;
  }

 private:
  // Waits until done (true) or until the run has gone `limit_` without
  // progress (false), looking at the count every twentieth of the limit.
  bool wait_for_end(std::unique_lock<std::mutex>& lk) {
    if (!progress_) return woken_.wait_for(lk, limit_, [this] { return done_; });
    const auto last = std::chrono::steady_clock::now() + 10 * limit_;
    std::uint64_t seen = progress_();
    auto deadline = std::chrono::steady_clock::now() + limit_;
    for (;;) {
      const auto step = std::min(std::chrono::steady_clock::now() + limit_ / 20, deadline);
      if (woken_.wait_until(lk, step, [this] { return done_; })) return true;
      const std::uint64_t now_seen = progress_();
      if (now_seen != seen) {
        seen = now_seen;
        deadline = std::min(std::chrono::steady_clock::now() + limit_, last);
      } else if (std::chrono::steady_clock::now() >= deadline) {
        return false;
      }
    }
  }

  void watch() {
    std::unique_lock<std::mutex> lk(mutex_);
    if (wait_for_end(lk)) return;
    fired_ = true;
    lk.unlock();
    stop_();
    lk.lock();
    if (woken_.wait_for(lk, limit_, [this] { return done_; })) return;
    std::fprintf(stderr, "hung for %lld ms, and stopping it did not end it: %s\n",
                 static_cast<long long>(2 * limit_.count()), what_.c_str());
    std::abort();
  }

  const std::chrono::milliseconds limit_;
  const std::function<void()> stop_;
  const std::string what_;
  const std::function<std::uint64_t()> progress_;
  mutable std::mutex mutex_;
  std::condition_variable woken_;
  bool done_ = false;
  bool fired_ = false;
  std::thread thread_;  // last: starts once the rest is built
};

inline std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// How a process pauses before each message it sends or takes.
struct Pauses {
  unsigned max_yields = 0;                 // csp::yield() 0..max_yields times
  unsigned sleep_one_in = 0;               // then, before one message in this many, a sleep (0: never)
  std::chrono::microseconds max_sleep{1};  // of 1..max_sleep
};

// Mostly a few yields, in one case of three a short sleep now and then.
inline Pauses draw_pauses(std::mt19937_64& rng) {
  Pauses p;
  p.max_yields = rng() % 4 == 0 ? 0 : 1 + static_cast<unsigned>(rng() % 6);
  if (rng() % 3 == 0) {
    p.sleep_one_in = 4 + static_cast<unsigned>(rng() % 29);
    p.max_sleep = std::chrono::microseconds(1 + rng() % 40);
  }
  return p;
}

inline csp::Priority draw_priority(std::mt19937_64& rng) {
  return rng() % 2 ? csp::Priority::high : csp::Priority::low;
}

// One process's pauses; pause() from that process only.
class Pacer {
 public:
  Pacer(const Pauses& pauses, std::uint64_t seed) : pauses_(pauses), rng_(seed) {}
  void pause() {
    if (pauses_.max_yields > 0)
      for (auto n = rng_() % (pauses_.max_yields + 1); n > 0; --n) csp::yield();
    if (pauses_.sleep_one_in > 0 && rng_() % pauses_.sleep_one_in == 0)
      csp::sleep_for(std::chrono::microseconds(1 + rng_() % static_cast<std::uint64_t>(pauses_.max_sleep.count())));
  }

 private:
  Pauses pauses_;
  std::mt19937_64 rng_;
};

}  // namespace test
