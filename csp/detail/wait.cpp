// Waiter claiming, parking and the channel queues (see wait.hpp).
#include "csp/detail/wait.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>

#include <boost/fiber/detail/cpu_relax.hpp>

#include "csp/detail/process.hpp"
#include "csp/errors.hpp"
#include "csp/scheduler.hpp"

namespace csp::detail {

void Spinlock::wait_until_free() noexcept {
  constexpr int spins_before_yield = 64;
  for (int spins = 0; locked_.load(std::memory_order_relaxed); ++spins) {
    if (spins < spins_before_yield) {
      cpu_relax();  // Boost.Fiber's spin-wait hint (a macro)
    } else {
      std::this_thread::yield();
    }
  }
}

namespace {

// The value a timed waiter stores in its context's twstatus: Boost's timer
// exchanges it for -2 on timeout, a waker CASes it to -1, so exactly one of
// the two reschedules the fiber (the same protocol as Boost's own channels).
std::intptr_t timed_token(const Waiter& w) { return reinterpret_cast<std::intptr_t>(&w); }

// Contexts on other threads, claimed under a lock still held: the first
// deferred_wake_count entries. Emptied before the fiber suspends, so it
// never carries over to another fiber. A lock rarely completes more than
// one waiter; when the buffer is full the wakes are issued at once, under
// the lock, which is correct, only slower.
constexpr std::size_t deferred_wake_capacity = 64;
constinit thread_local std::array<boost::fibers::context*, deferred_wake_capacity> deferred_wakes{};

}  // namespace

constinit thread_local std::size_t deferred_wake_count = 0;

void RecordQueue::push_back(Record& r) {
  r.prev = tail_;
  r.next = nullptr;
  (tail_ ? tail_->next : head_) = &r;
  tail_ = &r;
  r.linked = true;
}

Record* RecordQueue::pop_front() {
  Record* r = head_;
  if (r) erase(*r);
  return r;
}

void RecordQueue::erase(Record& r) {
  if (!r.linked) return;
  (r.prev ? r.prev->next : head_) = r.next;
  (r.next ? r.next->prev : tail_) = r.prev;
  r.prev = r.next = nullptr;
  r.linked = false;
}

void ChannelBase::throw_unbound(const char* use) {
  throw std::logic_error(std::string(use) +
                         ": the end is bound to no channel (default-constructed, or moved from); assign it an end of a Channel first");
}

void ChannelBase::throw_poisoned(const char* use) const {
  if (unbound_) throw_unbound(use);
  throw Poisoned(name_);
}

void ChannelBase::poison() {
  ChannelLock lk(lock_);
  if (poisoned_.load(std::memory_order_relaxed)) return;
  poisoned_.store(true, std::memory_order_release);
  wake_all_locked(readers_, WaitState::poisoned);
  wake_all_locked(writers_, WaitState::poisoned);
  wake_all_locked(room_waiters_, WaitState::poisoned);
  data_bell_.ring();
  room_bell_.ring();
}

// Called with a channel's lock held, whose release flushes any cross-thread
// wake this queues.
void Bell::wake() {
  SpinlockLock lk(lock_);
  if (Record* r = claim_front_locked(readers_)) complete(*r->waiter, WaitState::data, 0);
}

BellMark Bell::mark(std::size_t guard) {
  while (marks_.size() <= guard / 64) marks_.push_back(std::make_unique<BellWord>());
  BellWord& word = *marks_[guard / 64];
  word.marks.fetch_or(mark_bit(guard), std::memory_order_relaxed);
  return BellMark{this, &word, mark_bit(guard)};
}

WaitState Bell::wait(Waiter& w, Clock::time_point deadline) {
  ChannelLock lk(lock_);
  if (rung_.exchange(false, std::memory_order_acq_rel)) return WaitState::data;
  Record rec;
  rec.waiter = &w;
  readers_.push_back(rec);
  WaitState s = WaitState::waiting;
  if (deadline == Clock::time_point::max()) {
    s = park(w, lk.get());
    if (s == WaitState::data) return s;
    lk.lock();
  } else {
    park_until(w, lk.get(), deadline);
    lk.lock();
    s = resolve_timeout(w);
  }
  readers_.erase(rec);
  if (s == WaitState::refused) unwind_wait(w);
  return s;
}

Record* ChannelBase::claim_front_locked(RecordQueue& q) {
  // Records of waiters already won elsewhere (another ALT guard, a timeout,
  // the deadlock detector) are dropped on the way.
  while (Record* r = q.pop_front()) {
    if (try_claim(*r->waiter)) return r;
  }
  return nullptr;
}

void ChannelBase::wake_all_locked(RecordQueue& q, WaitState outcome) {
  while (Record* r = claim_front_locked(q)) complete(*r->waiter, outcome, r->guard);
}

// A CAS from `waiting`, so exactly one party wins even when several channels
// fire at once. Claims happen under the lock of the channel whose queue holds
// the record, so a woken waiter that relocks its channels knows every
// claimer has finished with it.
bool try_claim(Waiter& w) {
  WaitState expected = WaitState::waiting;
  return w.state.compare_exchange_strong(expected, WaitState::claiming, std::memory_order_acq_rel);
}

void complete(Waiter& w, WaitState outcome, std::size_t fired) {
  boost::fibers::context* ctx = w.ctx;
  const std::intptr_t token = timed_token(w);
  if (w.process) w.process->tracker->unblock(*w.process);
  w.fired = fired;
  w.state.store(outcome, std::memory_order_release);
  std::intptr_t expected = token;
  if (ctx->twstatus.compare_exchange_strong(expected, -1, std::memory_order_acq_rel) || expected == 0) {
    // Safe to defer: ctx stays parked until it is scheduled.
    boost::fibers::scheduler* local = runtime_scheduler_here;
    if (!local) local = boost::fibers::context::active()->get_scheduler();
    if (ctx->get_scheduler() == local) {
      local->schedule(ctx);
    } else {
      if (deferred_wake_count == deferred_wake_capacity) issue_deferred_wakes();
      remote_wakes_in_flight.fetch_add(1, std::memory_order_seq_cst);  // before ctx can run
      deferred_wakes[deferred_wake_count++] = ctx;
    }
  }
}

constinit thread_local std::uint64_t remote_wakes_here = 0;

std::atomic<std::uint64_t> remote_wakes_in_flight{0};

void issue_deferred_wakes() {
  const std::size_t count = deferred_wake_count;
  remote_wakes_here += count;
  for (std::size_t i = 0; i < count; ++i)
    deferred_wakes[i]->get_scheduler()->schedule_from_remote(deferred_wakes[i]);
  deferred_wake_count = 0;
  remote_wakes_in_flight.fetch_sub(count, std::memory_order_seq_cst);  // every notify() has returned
}

namespace {

// For a timed wait, or an untimed one of no process: false, with w refused,
// for a thread outside any Runtime; fibers there (par()'s children) may park.
// Who may park: the fibers of a runtime thread, and outside any Runtime the
// fibers that par() starts, which wake each other. A thread outside any
// Runtime (main(), a std::thread) may not: no process can be relied on to
// wake it, and no deadlock detector sees it, so it would hang. The check sits
// on the branch arm() takes anyway for a wait of no process (and for timed
// waits), so that a process's untimed wait pays nothing for it; the caller
// then unlinks and throws std::logic_error (unwind_wait()).
bool may_park(Waiter& w, boost::fibers::context* ctx) {
  if (runtime_scheduler_here || !ctx->is_context(boost::fibers::type::main_context)) return true;
  w.state.store(WaitState::refused, std::memory_order_relaxed);
  return false;
}

}  // namespace

bool arm(Waiter& w, bool timed) {
  boost::fibers::context* ctx = boost::fibers::context::active();
  w.ctx = ctx;
  if (timed) {
    ctx->twstatus.store(timed_token(w), std::memory_order_release);
    return may_park(w, ctx);
  }
  ctx->twstatus.store(0, std::memory_order_release);
  Process* p = process_of(ctx);
  if (!p) return may_park(w, ctx);
  const bool runnable = !p->tracker->aborting() && p->tracker->block(*p, w);
  if (runnable || !w.abortable) return true;
  // Nobody can wake us (or the run is unwinding): do not park, and so do
  // not stay counted as blocked (block() counted us if it found the deadlock).
  if (w.process) {
    p->tracker->unblock(*p);
    w.process = nullptr;
  }
  w.state.store(WaitState::aborted, std::memory_order_relaxed);
  p->waiting.store(nullptr, std::memory_order_relaxed);
  return false;
}

// Both sleeps release the lock themselves before suspending (rather than
// handing it to Boost, whose unlock is invisible to ThreadSanitizer). That is
// safe: no other fiber of this thread runs before the suspension, and a waker
// on another thread can only queue this fiber for this thread's dispatcher,
// which runs after the suspension.
WaitState sleep(Waiter& w, SpinlockLock& lk) {
  lk.unlock();
  flush_wakes();
  w.ctx->suspend();
  if (w.process) w.process->waiting.store(nullptr, std::memory_order_relaxed);
  return w.state.load(std::memory_order_acquire);
}

void sleep_until(Waiter& w, SpinlockLock& lk, Clock::time_point deadline) {
  lk.unlock();
  flush_wakes();
  w.ctx->wait_until(deadline);
}

WaitState park(Waiter& w, SpinlockLock& lk) {
  if (arm(w, false)) return sleep(w, lk);
  lk.unlock();
  flush_wakes();
  return w.state.load(std::memory_order_relaxed);
}

void park_until(Waiter& w, SpinlockLock& lk, Clock::time_point deadline) {
  if (arm(w, true)) {
    sleep_until(w, lk, deadline);
  } else {
    lk.unlock();
    flush_wakes();
  }
}

WaitState resolve_timeout(Waiter& w) {
  WaitState s = WaitState::waiting;
  if (w.state.compare_exchange_strong(s, WaitState::timed_out, std::memory_order_acq_rel)) {
    return WaitState::timed_out;
  }
  return s;
}

std::string describe_wait(const Waiter& w) {
  std::string text = w.op;
  if (w.channel) text += " channel '" + w.channel->name() + "'";
  if (w.channels) {
    text += w.channels->empty() ? " no channel" : " channels";
    const char* sep = " ";
    for (const ChannelBase* c : *w.channels) {
      text += sep;
      text += "'" + c->name() + "'";
      sep = ", ";
    }
  }
  return text;
}

void unwind_deadlock() { throw DeadlockUnwind{}; }

void unwind_wait(const Waiter& w) {
  if (w.state.load(std::memory_order_relaxed) == WaitState::refused) {
    throw std::logic_error("a thread outside any csp::Runtime would block " + describe_wait(w) +
                           "; only processes and par() children may wait");
  }
  unwind_deadlock();
}

}  // namespace csp::detail
