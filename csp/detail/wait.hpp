// Waiting machinery shared by channels, ALT and PAR.
//
// A fiber that must block builds one Waiter on its stack and links one Record
// per channel it waits on into that channel's reader or writer queue (a plain
// read or write: one record; an ALT: one per enabled input guard). Whoever
// makes the wait succeed (a writer, a reader, poison, the deadlock detector)
// must *claim* the Waiter first, by a CAS from `waiting`: exactly one wins,
// fills the payload, and complete() publishes the outcome and reschedules the
// waiter (locally, or through Boost's remote-ready queue from another thread).
// Locking: records are linked, unlinked and claimed only under the lock of
// the channel whose queue holds them; the deadlock detector claims without
// one, but only untimed waiters, which cannot run before they are
// rescheduled. An untimed park counts the process as blocked; its claimer
// uncounts it (Tracker, detail/process.hpp). Only fibers may park: a thread
// outside any Runtime is refused (arm()) and gets std::logic_error.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/fiber/context.hpp>

namespace csp::detail {

// A test-and-test-and-set lock guarding a channel (or a bell, or a small
// piece of runtime state) for a few instructions at a time. Taking it free
// costs one exchange; a thread that finds it taken watches it with the CPU's
// spin-wait hint and, after a while, gives up its time slice, so that a
// holder the OS has preempted can finish.
class Spinlock {
 public:
  void lock() noexcept {
    while (locked_.exchange(true, std::memory_order_acquire)) wait_until_free();
  }
  bool try_lock() noexcept { return !locked_.exchange(true, std::memory_order_acquire); }
  void unlock() noexcept { locked_.store(false, std::memory_order_release); }

 private:
  void wait_until_free() noexcept;
  std::atomic<bool> locked_{false};
};

using SpinlockLock = std::unique_lock<Spinlock>;
using Clock = std::chrono::steady_clock;

// `after` from `from`, saturating at the end of time: a timeout of
// duration::max() ("forever") must not wrap into the past and fire at once.
inline Clock::time_point deadline_after(Clock::time_point from, Clock::duration after) {
  if (after > Clock::time_point::max() - from) return Clock::time_point::max();
  return from + after;
}

struct Process;
class ChannelBase;
class Bell;

// The marks of 64 guards of a doorbell ALT, and which of them are armed
// (see Bell); one cache line.
struct alignas(64) BellWord {
  std::atomic<std::uint64_t> marks{0};
  std::atomic<std::uint64_t> armed{~std::uint64_t{0}};
};

// Where a channel rings a doorbell ALT: the ALT's bell, and the mark bit of
// the guard that watches the channel (see Bell). No bell: nobody watches.
struct BellMark {
  Bell* bell = nullptr;
  BellWord* word = nullptr;
  std::uint64_t bit = 0;

  void ring() const;
};

// How a wait ended. `claiming` is transient: held by a claimer between its CAS
// and complete(), always under a channel lock. `refused` is set by arm() alone,
// for a wait it would not park (see "Who may park").
enum class WaitState : int { waiting, claiming, data, poisoned, timed_out, aborted, refused };

struct Waiter {
  boost::fibers::context* ctx = nullptr;          // the parked fiber
  std::atomic<WaitState> state{WaitState::waiting};
  std::size_t fired = 0;                          // guard index of the record that won (ALT)
  Process* process = nullptr;                     // set when the park is counted as blocked
  const char* op = "";                            // what it waits for, for the deadlock dump and errors
  const ChannelBase* channel = nullptr;           // single channel waited on, or null
  const std::vector<ChannelBase*>* channels = nullptr;  // ALT: all channels waited on
  bool abortable = true;                          // false for PAR joins: children end first
};

// One entry in a channel queue. slot points at the payload: for a writer the
// value to take, for a blocking reader an std::optional<T> to fill; null for
// an ALT reader, which only learns that the channel became ready.
struct Record {
  Record* prev = nullptr;
  Record* next = nullptr;
  Waiter* waiter = nullptr;
  void* slot = nullptr;
  std::size_t guard = 0;
  bool linked = false;
};

// Intrusive FIFO of records; the owning channel's lock protects it.
class RecordQueue {
 public:
  bool empty() const { return head_ == nullptr; }
  Record* front() const { return head_; }
  void push_back(Record& r);
  Record* pop_front();
  void erase(Record& r);  // no-op if r was already popped

 private:
  Record* head_ = nullptr;
  Record* tail_ = nullptr;
};

// The type-independent half of a channel: lock, poison flag, wait queues.
// The unbound channel (channel.hpp) is one made poisoned and marked unbound;
// nothing ever changes either.
class ChannelBase {
 public:
  struct Unbound {};
  ChannelBase(std::string name, std::size_t capacity) : name_(std::move(name)), capacity_(capacity) {}
  explicit ChannelBase(Unbound) : capacity_(0), poisoned_(true), unbound_(true) {}
  virtual ~ChannelBase() = default;
  ChannelBase(const ChannelBase&) = delete;
  ChannelBase& operator=(const ChannelBase&) = delete;

  const std::string& name() const { return name_; }
  bool poisoned() const { return poisoned_.load(std::memory_order_acquire); }
  void poison();
  // std::logic_error for `use` (the member of an end, or of Alt, that was
  // called) of the unbound channel.
  void require_bound(const char* use) const {
    if (unbound_) throw_unbound(use);
  }
  // The poison check's slow path, which every operation on an unbound end
  // takes: std::logic_error for `use` of the unbound channel, else Poisoned.
  [[noreturn]] void throw_poisoned(const char* use) const;

  // Lock must be held. True if a read would not block (data, or poison).
  virtual bool ready_locked() const = 0;
  // Lock must be held. True if a write would not block: a buffered channel
  // with a free slot (or poison, which makes the write throw at once).
  virtual bool room_locked() const = 0;
  // No lock: ready_locked() and room_locked() as last published (see
  // channel.hpp).
  bool ready_hint() const { return poisoned() || ready_hint_.load(std::memory_order_relaxed); }
  bool room_hint() const { return poisoned() || room_hint_.load(std::memory_order_relaxed); }
  std::size_t capacity() const { return capacity_; }

  Spinlock lock_;
  RecordQueue readers_;  // guarded by lock_
  RecordQueue writers_;  // guarded by lock_
  RecordQueue room_waiters_;  // ALTs waiting for a free slot; guarded by lock_
  // The bells of doorbell ALTs watching this channel (alt.hpp), guarded by
  // lock_: data_bell_ is rung after every change that may let its reader
  // read without blocking (a value buffered, a writer parked, poison),
  // room_bell_ after every change that frees a slot for its writer (and by
  // poison). Rung with lock_ held: the lock order is channel, then bell.
  BellMark data_bell_;
  BellMark room_bell_;

 protected:
  // Lock must be held. Claims and completes the first live record of q with
  // the given outcome; returns it (slot still valid) or null if none is live.
  Record* claim_front_locked(RecordQueue& q);
  void publish_hints(bool ready, bool room) {
    ready_hint_.store(ready, std::memory_order_relaxed);
    room_hint_.store(room, std::memory_order_relaxed);
  }
  void wake_all_locked(RecordQueue& q, WaitState outcome);
  [[noreturn]] static void throw_unbound(const char* use);

  std::string name_;
  std::size_t capacity_;
  std::atomic<bool> poisoned_{false};
  std::atomic<bool> ready_hint_{false};
  std::atomic<bool> room_hint_{false};
  const bool unbound_ = false;
};

// The bell of a doorbell ALT: a one-bit event with one waiter, the ALT's
// owner, who clears it before each poll of its channels and then waits, and
// one mark bit per guard, which says which channels rang.
// ring() sets the ringing guard's mark, then the bell, and if the bell was
// clear wakes the waiter when parked; wait() returns at once if it was rung
// since the last clear, else parks until the next ring or the deadline.
// Every ring is a release on its mark word and on rung_ (read-modify-writes,
// so runs of rings form release sequences), and the owner clears both with
// acquire read-modify-writes, so a channel change made before a ring is
// visible to the poll that clears its mark, and to the poll that follows the
// clear of the bell or the wait that sees it.
// Marks: only the owner clears a mark, and only just before it looks at the
// channel, so a mark is clear only while its channel has not rung since a
// look that found it not ready. A poll may therefore skip every guard whose
// mark is clear. Mark words are allocated by the owner as guards are added
// and never move, so channels ring them without a lock.
// Arming: a ring always sets its mark, but rings the bell (and so wakes the
// owner) only if its guard is armed; the owner arms the guards it has
// enabled (arm()), so a channel whose guard is switched off, such as a
// router's room guard while nothing waits for room, never wakes it in vain.
// A ring's mark (seq_cst) comes before its look at the armed bits, and
// arm() is followed by a full fence before the owner's next poll reads the
// marks, so a ring that finds its guard not yet armed leaves a mark that
// poll sees.
class Bell final : public ChannelBase {
 public:
  explicit Bell(std::string name) : ChannelBase(std::move(name), 0) {}
  bool ready_locked() const override { return rung_.load(std::memory_order_relaxed); }
  bool room_locked() const override { return true; }

  void ring(BellWord& word, std::uint64_t bit) {
    word.marks.fetch_or(bit, std::memory_order_seq_cst);
    if (!(word.armed.load(std::memory_order_seq_cst) & bit)) return;  // switched off: the mark waits for the poll
    if (!rung_.exchange(true, std::memory_order_acq_rel)) wake();  // else already rung, not yet seen
  }
  void clear() {
    if (rung_.load(std::memory_order_relaxed)) rung_.exchange(false, std::memory_order_acq_rel);
  }
  // w describes the wait for the deadlock dump. Returns data (rung),
  // timed_out (deadline first) or aborted (deadlocked run: unwind); throws
  // the error of a wait arm() refuses.
  WaitState wait(Waiter& w, Clock::time_point deadline);

  // Owner only. The mark of guard `guard`, set (so that the first poll looks
  // at its channel); allocated on first use.
  BellMark mark(std::size_t guard);
  // Owner only: the 64 marks of guards 64 w .. 64 w + 63 (0 if none added).
  std::uint64_t marks(std::size_t w) const {
    return w < marks_.size() ? marks_[w]->marks.load(std::memory_order_relaxed) : 0;
  }
  // Owner only, before it looks at guard's channel: clears its mark.
  void clear_mark(std::size_t guard) {
    marks_[guard / 64]->marks.fetch_and(~mark_bit(guard), std::memory_order_acq_rel);
  }
  // Owner only, after finding guard's channel ready: keeps it marked, since
  // it may stay ready after the owner acts on it.
  void keep_mark(std::size_t guard) {
    marks_[guard / 64]->marks.fetch_or(mark_bit(guard), std::memory_order_relaxed);
  }
  // Owner only, before its next poll: the guards 64 w .. 64 w + 63 whose
  // rings wake it (all, until first armed).
  void arm(std::size_t w, std::uint64_t armed) {
    if (w >= marks_.size()) return;
    marks_[w]->armed.store(armed, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);
  }

 private:
  static std::uint64_t mark_bit(std::size_t guard) { return std::uint64_t{1} << (guard % 64); }
  void wake();

  // Set only by ring(), cleared only by the waiter. Once a ring finds it
  // clear, that ring wakes the waiter if it is parked (under lock_).
  std::atomic<bool> rung_{false};
  std::vector<std::unique_ptr<BellWord>> marks_;  // stable addresses
};

inline void BellMark::ring() const {
  if (bell) bell->ring(*word, bit);
}

// Claiming: try_claim() wins the waiter or reports a lost race; complete()
// (winner only, under the channel lock) publishes the outcome and wakes it.
// A waiter on this thread is made ready at once; one on another thread is
// woken by flush_wakes() once the lock is released — waking a sleeping thread
// is a system call, and a lock held across it gets the waker preempted while
// the woken thread spins on that very lock.
bool try_claim(Waiter& w);
void complete(Waiter& w, WaitState outcome, std::size_t fired);

// Cross-thread wakes deferred on this thread and not yet issued. Every
// channel unlock reads it, so it is a constant-initialised thread_local
// that the inline test below reaches without a call.
extern constinit thread_local std::size_t deferred_wake_count;
void issue_deferred_wakes();
// Cross-thread wakes deferred and not yet through their scheduler's
// notify(), process-wide: a woken fiber can end, and its thread with it,
// before the waker's notify() returns, so a runtime thread keeps its
// scheduler until none is in flight (Runtime's worker_main).
extern std::atomic<std::uint64_t> remote_wakes_in_flight;
// Counted on the thread that wakes: the processes of other threads it woke.
// Read and reset by the runtime thread itself.
extern constinit thread_local std::uint64_t remote_wakes_here;
inline void flush_wakes() {
  if (deferred_wake_count != 0) issue_deferred_wakes();
}

// A held channel lock that issues the deferred cross-thread wakes when it is
// released (by the destructor, or by sleep() just before the fiber suspends).
class ChannelLock {
 public:
  explicit ChannelLock(Spinlock& l) : lk_(l) {}
  ~ChannelLock() {
    if (lk_.owns_lock()) lk_.unlock();
    flush_wakes();
  }
  ChannelLock(const ChannelLock&) = delete;
  ChannelLock& operator=(const ChannelLock&) = delete;
  SpinlockLock& get() { return lk_; }
  void lock() { lk_.lock(); }
  void unlock() {
    lk_.unlock();
    flush_wakes();
  }

 private:
  SpinlockLock lk_;
};

// Parking is two steps. arm(), with the lock of every channel holding a
// record of w, makes w claimable: it records the fiber, and for an untimed
// wait counts the process as blocked; it returns false (w is then `aborted`)
// if the run is deadlocked, or (w `refused`) if the caller may not park at
// all, and the caller must then unlink and unwind_wait() instead.
// sleep() / sleep_until() then release lk — the one lock still held; others
// may be released between the steps — and suspend until claimed (or until
// the deadline: the caller relocks and resolves a `waiting` state, a timeout
// nobody claimed, with resolve_timeout()). sleep() returns the outcome.
bool arm(Waiter& w, bool timed);
WaitState sleep(Waiter& w, SpinlockLock& lk);
void sleep_until(Waiter& w, SpinlockLock& lk, Clock::time_point deadline);
// Both steps for a wait under a single lock; lk is unlocked on return. If
// arm() fails, park() returns its outcome and park_until() returns at once,
// leaving it for resolve_timeout() to report.
WaitState park(Waiter& w, SpinlockLock& lk);
void park_until(Waiter& w, SpinlockLock& lk, Clock::time_point deadline);
WaitState resolve_timeout(Waiter& w);  // caller holds every lock w's records live under

// What w waits on, as the deadlock dump and errors say it: "reading channel 'c'".
std::string describe_wait(const Waiter& w);

// Throws the internal unwinding signal that ends a process of a deadlocked run.
[[noreturn]] void unwind_deadlock();
// Ends a wait that arm() failed or the deadlock detector aborted, its records
// unlinked and its locks released: std::logic_error naming the wait if it was
// refused, else unwind_deadlock().
[[noreturn]] void unwind_wait(const Waiter& w);

}  // namespace csp::detail
