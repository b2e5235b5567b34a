// Tracker: alive/blocked accounting and the deadlock abort (see process.hpp).
#include <algorithm>
#include <sstream>

#include "csp/detail/process.hpp"

namespace csp::detail {

void Tracker::add(Process& p) {
  p.tracker = this;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    processes_.push_back(&p);
  }
  counts_.fetch_add(one_alive, std::memory_order_acq_rel);
}

void Tracker::remove(Process& p) {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    processes_.erase(std::find(processes_.begin(), processes_.end(), &p));
  }
  const std::uint64_t v = counts_.fetch_sub(one_alive, std::memory_order_acq_rel) - one_alive;
  const std::uint64_t alive = v >> 32;
  if (alive == 0) {
    on_all_ended_();
  } else if ((v & blocked_mask) == alive) {
    abort_run(nullptr);
  }
}

bool Tracker::block(Process& p, Waiter& w) {
  w.process = &p;
  p.waiting.store(&w, std::memory_order_release);
  const std::uint64_t v = counts_.fetch_add(1, std::memory_order_acq_rel) + 1;
  if ((v & blocked_mask) != (v >> 32)) return true;
  abort_run(&p);
  return false;
}

void Tracker::unblock(Process&) { counts_.fetch_sub(1, std::memory_order_acq_rel); }

std::string Tracker::deadlock_dump() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return dump_;
}

void Tracker::abort_run(const Process* self) {
  bool expected = false;
  if (!aborting_.compare_exchange_strong(expected, true, std::memory_order_acq_rel)) return;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    dump_ = describe_locked();
    // Everyone is parked and nobody else can claim them: wake all to unwind.
    for (Process* q : processes_) {
      Waiter* w = q->waiting.load(std::memory_order_acquire);
      if (q == self || !w || !w->abortable) continue;
      if (try_claim(*w)) complete(*w, WaitState::aborted, 0);
    }
  }
  flush_wakes();
}

std::string Tracker::describe_locked() const {
  std::ostringstream out;
  out << "deadlock: all " << processes_.size() << " live processes wait on channels, no timer pending";
  for (const Process* q : processes_) {
    out << "\n  process '" << q->name << "' (thread " << q->thread << "): ";
    if (const Waiter* w = q->waiting.load(std::memory_order_acquire)) {
      out << describe_wait(*w);
    } else {
      out << "ending";
    }
  }
  return out.str();
}

}  // namespace csp::detail
