// Book-keeping of a run: the processes alive and the deadlock detector.
//
// Tracker packs two counters into one atomic word — processes alive (high
// half) and processes blocked on an untimed wait (low half) — so every update
// returns a consistent snapshot. A process is counted blocked just before it
// parks (under the lock of a channel it waits on); the party that claims it
// uncounts it before waking it. Timed waits are never counted. Hence
// `blocked == alive > 0` means no process can run and nobody will wake one:
// the state is stable, and whoever observes it (the last process to block, or
// a process ending) aborts the run. Abort is one-shot: it writes the dump,
// then claims every parked abortable waiter with `aborted`; from then on
// every park returns `aborted` at once, so all processes unwind.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <boost/fiber/scheduler.hpp>

#include "csp/detail/wait.hpp"
#include "csp/scheduler.hpp"

namespace csp::detail {

class Tracker;

struct Process {
  std::string name;
  unsigned thread = 0;
  Priority priority = Priority::high;     // its PAR children's too
  Tracker* tracker = nullptr;
  std::size_t stack_size = 256 * 1024;    // for the fibers of its PAR children
  std::atomic<Waiter*> waiting{nullptr};  // published while counted as blocked
};

class Tracker {
 public:
  explicit Tracker(std::function<void()> on_all_ended) : on_all_ended_(std::move(on_all_ended)) {}

  void add(Process& p);
  void remove(Process& p);  // p has ended; may finish or abort the run
  // Counts p as blocked on w. Returns false if the run is (now) deadlocked:
  // the caller must not park and should unwind.
  bool block(Process& p, Waiter& w);
  void unblock(Process& p);
  bool aborting() const { return aborting_.load(std::memory_order_acquire); }
  std::uint64_t alive() const { return counts_.load(std::memory_order_acquire) >> 32; }
  std::string deadlock_dump() const;  // empty unless the run deadlocked

 private:
  static constexpr std::uint64_t one_alive = std::uint64_t{1} << 32;
  static constexpr std::uint64_t blocked_mask = one_alive - 1;

  void abort_run(const Process* self);
  std::string describe_locked() const;

  std::atomic<std::uint64_t> counts_{0};
  std::atomic<bool> aborting_{false};
  mutable std::mutex mutex_;           // guards processes_ and dump_
  std::vector<Process*> processes_;
  std::string dump_;
  std::function<void()> on_all_ended_;
};

// The process the calling fiber runs, or null outside a Runtime.
Process* current_process();
// The process fiber ctx runs (ctx: the calling fiber's context).
Process* process_of(boost::fibers::context* ctx);

// The scheduler of the calling runtime thread (null on other threads); a
// runtime thread sets it on start and clears it on exit.
boost::fibers::scheduler* thread_scheduler();
void set_thread_scheduler(boost::fibers::scheduler* s);

}  // namespace csp::detail

namespace csp::detail {

// The signal that unwinds a process of a deadlocked run. Deliberately not a
// std::exception, so `catch (const std::exception&)` in user code lets it pass.
struct DeadlockUnwind {};

}  // namespace csp::detail
