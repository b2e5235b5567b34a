// Book-keeping of a run: the processes alive and the deadlock detector.
//
// Tracker counts, for each runtime thread, the processes of that thread
// alive and those blocked on an untimed wait, in one atomic word per thread
// (on a cache line of its own) together with a version that every update
// advances. A process is counted blocked just before it parks (under the
// lock of a channel it waits on); the party that claims it uncounts it
// before waking it, in the word of the process's thread. Timed waits are
// never counted, and a pending csp::Arrivals counts as a process able to run.
// `blocked == alive > 0` over the whole run is a deadlock: the process that
// completes that state finds it (survey(), in tracker.cpp) and aborts the
// run, once: the dump is written, every parked abortable waiter is claimed
// with `aborted`, and every later park returns `aborted` at once, so all
// processes unwind. Nothing alive ends the run. Every thread updates the
// words with atomics; a process's own block and end touch only its own.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <boost/intrusive/list.hpp>

#include "csp/priority.hpp"

namespace csp {
class Arrivals;
}  // namespace csp

namespace csp::detail {

class Tracker;
struct Waiter;

struct Process {
  boost::intrusive::list_member_hook<> alive;  // in its Tracker's list while alive
  std::string name;
  unsigned thread = 0;
  Priority priority = Priority::high;     // its PAR children's too
  Tracker* tracker = nullptr;
  std::size_t stack_size = 256 * 1024;    // for the fibers of its PAR children
  std::atomic<Waiter*> waiting{nullptr};  // published while counted as blocked
};

class Tracker {
 public:
  Tracker(unsigned threads, std::function<void()> on_all_ended);

  // p.thread must name one of the tracker's threads. Throws
  // std::length_error past max_processes_per_thread.
  void add(Process& p);
  void remove(Process& p);  // p has ended; may finish or abort the run
  // Counts p as blocked on w. Returns false if the run is (now) deadlocked:
  // the caller must not park and should unwind.
  bool block(Process& p, Waiter& w);
  void unblock(Process& p);
  bool aborting() const { return aborting_.load(std::memory_order_acquire); }
  // An Arrivals attached on `thread` (one per thread): while it is pending,
  // the run counts as able to go on. unwatch() before `a` goes.
  void watch(unsigned thread, const Arrivals* a);
  void unwatch(const Arrivals* a) noexcept;
  std::uint64_t alive() const;
  std::string deadlock_dump() const;  // what each process waited on; only once aborting()

  static constexpr unsigned count_bits = 21;
  static constexpr std::uint64_t max_processes_per_thread = (std::uint64_t{1} << count_bits) - 1;

 private:
  // A thread's word: blocked processes in the low count_bits, alive ones in
  // the next count_bits, the version above them (it wraps harmlessly).
  static constexpr std::uint64_t one_blocked = 1;
  static constexpr std::uint64_t one_alive = std::uint64_t{1} << count_bits;
  static constexpr std::uint64_t one_version = std::uint64_t{1} << (2 * count_bits);
  static std::uint64_t blocked_of(std::uint64_t word) { return word & max_processes_per_thread; }
  static std::uint64_t alive_of(std::uint64_t word) { return (word >> count_bits) & max_processes_per_thread; }
  static std::uint64_t version_of(std::uint64_t word) { return word >> (2 * count_bits); }
  static bool all_blocked(std::uint64_t word) { return blocked_of(word) == alive_of(word); }

  struct alignas(64) Counts {
    std::atomic<std::uint64_t> word{0};
    std::atomic<const Arrivals*> arrivals{nullptr};  // changes only at attach and detach
  };
  enum class Run { going, deadlocked, ended };

  std::atomic<std::uint64_t>& counts_of(const Process& p) { return counts_[p.thread].word; }
  Run survey() const;
  bool abort_run(const Process* self);  // false if an abort had already started
  std::string describe_locked() const;

  const unsigned threads_;
  std::unique_ptr<Counts[]> counts_;
  std::atomic<bool> ended_{false};
  std::atomic<bool> aborting_{false};
  mutable std::mutex mutex_;  // guards processes_, dump_ and dump_processes_
  // Linked through the processes themselves: adding or removing one
  // allocates nothing and takes constant time.
  boost::intrusive::list<Process, boost::intrusive::member_hook<Process, boost::intrusive::list_member_hook<>,
                                                                &Process::alive>>
      processes_;
  std::string dump_;                   // empty if there was no memory to write it
  std::size_t dump_processes_ = 0;
  std::function<void()> on_all_ended_;
};

}  // namespace csp::detail

namespace csp::detail {

// The signal that unwinds a process of a deadlocked run. Deliberately not a
// std::exception, so `catch (const std::exception&)` in user code lets it pass.
struct DeadlockUnwind {};

}  // namespace csp::detail
