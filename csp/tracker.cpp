// Tracker: alive/blocked accounting and the deadlock abort (see process.hpp).
#include <new>
#include <stdexcept>
#include <string>
#include <sstream>

#include "csp/detail/process.hpp"
#include "csp/detail/wait.hpp"
#include "csp/scheduler.hpp"

namespace csp::detail {

namespace {

// The first line of a deadlock's report.
std::string deadlock_headline(std::size_t processes) {
  return "deadlock: all " + std::to_string(processes) + " live processes wait on channels, no timer pending";
}

}  // namespace

Tracker::Tracker(unsigned threads, std::function<void()> on_all_ended)
    : threads_(threads), counts_(std::make_unique<Counts[]>(threads)), on_all_ended_(std::move(on_all_ended)) {}

void Tracker::add(Process& p) {
  p.tracker = this;
  std::atomic<std::uint64_t>& counts = counts_of(p);
  std::uint64_t word = counts.load();
  do {
    if (alive_of(word) == max_processes_per_thread)
      throw std::length_error("csp: more than " + std::to_string(max_processes_per_thread) +
                              " processes alive on runtime thread " + std::to_string(p.thread));
  } while (!counts.compare_exchange_weak(word, word + one_alive + one_version));
  std::lock_guard<std::mutex> lk(mutex_);
  processes_.push_back(p);
}

void Tracker::remove(Process& p) {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    processes_.erase(processes_.iterator_to(p));
  }
  const std::uint64_t word = counts_of(p).fetch_add(one_version - one_alive) + one_version - one_alive;
  if (!all_blocked(word)) return;
  switch (survey()) {
    case Run::going:
      return;
    case Run::deadlocked:
      abort_run(nullptr);
      return;
    case Run::ended:
      if (!ended_.exchange(true)) on_all_ended_();
      return;
  }
}

bool Tracker::block(Process& p, Waiter& w) {
  w.process = &p;
  p.waiting.store(&w, std::memory_order_release);
  const std::uint64_t word = counts_of(p).fetch_add(one_version + one_blocked) + one_version + one_blocked;
  if (!all_blocked(word) || survey() != Run::deadlocked) return true;
  // Processes of two threads may find the deadlock at once. The one whose
  // abort starts unwinds at once; the other parks, and the abort claims it.
  return !abort_run(&p);
}

void Tracker::unblock(Process& p) { counts_of(p).fetch_add(one_version - one_blocked); }

void Tracker::watch(unsigned thread, const Arrivals* a) { counts_[thread % threads_].arrivals.store(a); }

void Tracker::unwatch(const Arrivals* a) noexcept {
  for (unsigned t = 0; t < threads_; ++t) {
    const Arrivals* expected = a;
    counts_[t].arrivals.compare_exchange_strong(expected, nullptr);
  }
}

std::uint64_t Tracker::alive() const {
  std::uint64_t alive = 0;
  for (unsigned t = 0; t < threads_; ++t) alive += alive_of(counts_[t].word.load());
  return alive;
}

// Why the survey is sound. `blocked == alive > 0` over the whole run means
// no process can run and nobody will wake one: the state is stable. Only a
// process that makes its own thread's word all blocked (by blocking, or by
// ending) can complete that state, so only it surveys the other words: it
// reads them all twice, and if the versions of both reads add up the same,
// no word changed between them, so all were true at one instant. The last
// thread to reach the state sees the others', since its update precedes its
// reads in the single order of sequentially consistent operations. A survey
// that finds every word all blocked aborts the run; one that finds nothing
// alive ends it (once, though the last processes of two threads may both
// see it). Work that threads hand each other outside channels
// (csp::Arrivals) is seen too: a survey that finds an Arrivals pending
// between its two reads says the run goes on, since the handler will wake a
// process for it. Since a process's own block and end touch only its
// thread's word, threads that each wake their own processes never contend.
//
// Two reads of every thread's words whose versions add up to the same sum
// saw the same words, all true at one instant: a word changes only by
// adding one to its version (until, some four million changes on, the
// version wraps). A thread with a process able to run means the run goes
// on (that process will survey when it blocks or ends). Allocates nothing:
// it runs where memory may have run out.
Tracker::Run Tracker::survey() const {
  for (;;) {
    std::uint64_t alive = 0;
    std::uint64_t versions = 0;
    for (unsigned t = 0; t < threads_; ++t) {
      const std::uint64_t word = counts_[t].word.load();
      if (!all_blocked(word)) return Run::going;
      alive += alive_of(word);
      versions += version_of(word);
    }
    for (unsigned t = 0; t < threads_; ++t)
      if (const Arrivals* a = counts_[t].arrivals.load(); a && a->pending()) return Run::going;
    std::uint64_t versions_again = 0;
    for (unsigned t = 0; t < threads_; ++t) {
      const std::uint64_t word = counts_[t].word.load();
      if (!all_blocked(word)) return Run::going;
      versions_again += version_of(word);
    }
    if (versions_again == versions) return alive == 0 ? Run::ended : Run::deadlocked;
  }
}

std::string Tracker::deadlock_dump() const {
  std::lock_guard<std::mutex> lk(mutex_);
  if (!dump_.empty()) return dump_;
  return deadlock_headline(dump_processes_) + " (no memory was left to say on what)";
}

bool Tracker::abort_run(const Process* self) {
  bool expected = false;
  if (!aborting_.compare_exchange_strong(expected, true, std::memory_order_acq_rel)) return false;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    dump_processes_ = processes_.size();
    try {
      dump_ = describe_locked();
    } catch (const std::bad_alloc&) {
      // Unwinding the processes matters more than naming their waits.
    }
    // Everyone waits (parked, or about to park having found the deadlock
    // too) and nobody else can claim them: wake all to unwind.
    for (Process& q : processes_) {
      Waiter* w = q.waiting.load(std::memory_order_acquire);
      if (&q == self || !w || !w->abortable) continue;
      if (try_claim(*w)) complete(*w, WaitState::aborted, 0);
    }
  }
  flush_wakes();
  return true;
}

std::string Tracker::describe_locked() const {
  std::ostringstream out;
  out << deadlock_headline(processes_.size());
  for (const Process& q : processes_) {
    out << "\n  process '" << q.name << "' (thread " << q.thread << "): ";
    if (const Waiter* w = q.waiting.load(std::memory_order_acquire)) {
      out << describe_wait(*w);
    } else {
      out << "ending";
    }
  }
  return out.str();
}

}  // namespace csp::detail
