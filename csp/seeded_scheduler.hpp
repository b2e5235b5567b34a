// SeededScheduler: a test scheduler that runs the ready processes in an
// order drawn from a seeded pseudo-random sequence, so that a test can try a
// program under many interleavings and replay any one of them by its seed.
// At every switch it takes one ready fiber uniformly at random (splitmix64:
// the same draws on every standard library), among the high-priority ones
// while any is ready, then among the low ones; `mix_priorities` draws from
// both levels alike. A yield always switches when another fiber is ready.
// Determinism: on ONE runtime thread (RuntimeOptions{.threads = 1}) a program
// that uses no timers runs the same schedule for a seed every time. Timers
// (read_for, ALT timeouts, sleep_for) fire by the wall clock; on several
// threads each draws its own sequence but wakes between them follow the OS.
// Boost's dispatcher (timers, remote wakes, ended fibers) is not drawn: it
// runs when nothing else is ready, after a notify(), or every dispatch_period
// picks. No Arrivals, no ThreadTimes accounts, no spinning: an idle thread
// sleeps until notify() or its next timer.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "csp/scheduler.hpp"

namespace csp {

class SeededScheduler final : public Scheduler {
 public:
  explicit SeededScheduler(std::uint64_t seed, bool mix_priorities = false)
      : state_(seed), mix_priorities_(mix_priorities) {}

  void make_room_for_fiber() override;
  boost::fibers::fiber_properties* new_properties(boost::fibers::context* ctx) override;
  void awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept override;
  boost::fibers::context* pick_next() noexcept override;
  bool has_ready_fibers() const noexcept override;
  void suspend_until(std::chrono::steady_clock::time_point const& when) noexcept override;
  void notify() noexcept override;

  // Fibers picked so far (the dispatcher's runs not counted).
  std::uint64_t picks() const { return picks_; }

 private:
  static constexpr unsigned dispatch_period = 32;

  std::uint64_t next_random() noexcept;
  std::size_t below(std::size_t n) noexcept;  // uniform in [0, n), n > 0
  bool take_notification() noexcept;

  // Ready fibers, in no order (a pick swaps the last into its place); each
  // has room for every fiber of the thread (make_room_for_fiber), so
  // awakened() never allocates.
  std::vector<boost::fibers::context*> high_;  // high priority, and fibers of no process
  std::vector<boost::fibers::context*> low_;
  std::size_t fibers_ = 0;  // fibers given properties: a bound on those ready
  std::uint64_t state_;     // splitmix64
  const bool mix_priorities_;
  std::uint64_t picks_ = 0;
  boost::fibers::context* dispatcher_ = nullptr;  // set while it is ready
  unsigned picks_since_dispatch_ = 0;
  std::mutex mutex_;  // orders notify() against the sleeper's check
  std::condition_variable wakeup_;
  std::atomic<bool> notified_{false};
};

// The seed of stream `stream` (a thread, a rank) derived from `seed`:
// stream 0 is the seed itself, the others are scattered by splitmix64's
// mixing, so no two streams are shifts of one sequence.
std::uint64_t seed_of_stream(std::uint64_t seed, std::uint64_t stream);

// A factory for RuntimeOptions::scheduler: thread t draws from
// seed_of_stream(seed, t).
SchedulerFactory seeded_scheduler(std::uint64_t seed, bool mix_priorities = false);

}  // namespace csp
