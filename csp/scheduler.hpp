// Per-thread scheduling for Runtime: the replaceable piece.
//
// Each OS thread of a Runtime installs one Scheduler, made by the Runtime's
// SchedulerFactory. A Scheduler is a Boost.Fiber algorithm whose per-fiber
// properties are ProcessProps, so the runtime can find the process a fiber
// belongs to (and a virtual-time scheduler can keep a clock per process).
// FifoScheduler is the default: ready fibers in FIFO order, high priority
// first, then a short spin and a sleep when idle (its rules at its class).
// Arrivals hand a thread work outside its channels: the scheduler runs
// their handler at its next switch, and an idle thread stops waiting.
// A scheduler is used by its own thread only, but for notify() (a wake from
// another thread) and Arrivals::signal(), which any thread may call; its
// ThreadTimes accounts are written by that thread alone.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include <boost/fiber/algo/algorithm.hpp>
#include <boost/fiber/context.hpp>
#include <boost/fiber/properties.hpp>
#include <boost/fiber/scheduler.hpp>

#include "csp/priority.hpp"

namespace csp {

namespace detail {
struct Process;

// Sets aside, on the calling thread, the memory of the next properties
// made there (none if it already holds some). Throws std::bad_alloc.
void reserve_properties();
// Frees the calling thread's reserve, if any; a thread that reserved
// calls it before it exits.
void release_properties_reserve() noexcept;
}  // namespace detail

// Boost.Fiber makes a fiber's properties when the fiber is first made
// ready, inside a noexcept call where std::bad_alloc would end the program.
// So the runtime sets their memory aside beforehand, where a failure can be
// reported (reserve_properties()), and these allocation functions take it.
class ProcessProps : public boost::fibers::fiber_properties {
 public:
  explicit ProcessProps(boost::fibers::context* ctx, bool virtual_time = false)
      : fiber_properties(ctx), virtual_time(virtual_time) {}
  // The calling thread's reserve if it holds one, else the heap.
  static void* operator new(std::size_t size);
  static void operator delete(void* p) noexcept;
  // Room for any properties class (checked where each is defined).
  static constexpr std::size_t reserve_bytes = 128;
  detail::Process* process = nullptr;  // null for fibers that are not csp processes
  const bool virtual_time;             // these are VirtualProps (virtual_time.hpp)
  bool yielded = false;                // set by csp::yield(), cleared when the fiber is ready again
  bool behind_all = false;             // set by csp::yield_to_all(), cleared likewise
  bool ahead = false;                  // set by csp::yield_to_urgent(), cleared likewise
};

// The base of the runtime's schedulers.
class Scheduler : public boost::fibers::algo::algorithm_with_properties<ProcessProps> {
 public:
  // Called on the scheduler's thread before a fiber starts there, where an
  // exception is reported as a process that could not start: sets aside
  // the fiber's properties (and, in a derived scheduler, room in its ready
  // set), so that Boost's noexcept awakened() need allocate nothing.
  virtual void make_room_for_fiber();
  // True if the running process should offer the thread now (see
  // csp::yield_requested()); called on the scheduler's thread. The default
  // keeps no such rule and says no.
  virtual bool yield_requested() const noexcept { return false; }
  // Whether csp::yield_to_all() may put the caller behind the other ready
  // processes: some is ready, and the scheduler has the rule. Default: no.
  virtual bool others_ready() const noexcept { return false; }
};

// How one thread's time divides; written by that thread only. From the
// start of its accounts, the thread's time is cut at every idle wait into
// running (processes, and the switches between them), spinning and
// sleeping, so that the three add up to the time since the start: an awake
// interval is closed at the clock reading that opens the next wait, and
// each wait's phases at the readings that end them. These readings are the
// ones the idle wait makes anyway (its spin deadline, its end), so a busy
// thread pays no clock for its accounts. The clock reads awake_since as the
// start of the interval now open, which is running time until the next wait.
struct ThreadTimes {
  std::chrono::steady_clock::duration running{};   // processes and switches
  std::chrono::steady_clock::duration spinning{};  // idle, watching for a wake
  std::chrono::steady_clock::duration sleeping{};  // idle, asleep in the OS
  std::uint64_t waits = 0;    // idle waits begun
  std::uint64_t sleeps = 0;   // of which went on to sleep in the OS
  std::chrono::steady_clock::time_point awake_since{};
  // Starts the accounts at `now` (all zero).
  void start(std::chrono::steady_clock::time_point now) { *this = ThreadTimes{}, awake_since = now; }
  // Closes the open running interval at `now`.
  void close(std::chrono::steady_clock::time_point now) {
    running += now - awake_since;
    awake_since = now;
  }
};

// Called once on each runtime thread, with that thread's index.
using SchedulerFactory = std::function<Scheduler*(unsigned thread)>;

// How long an idle thread of a runtime of `threads` threads watches for a
// wake before it sleeps, on a machine of `hardware_threads` (0: unknown,
// taken as enough): 50 us, or none when the threads outnumber the hardware.
std::chrono::microseconds idle_spin(unsigned threads, unsigned hardware_threads);

class FifoScheduler;

// csp::Arrivals: work handed to one runtime thread outside its channels, by
// other threads, which the thread notices at its next switch instead of
// being woken for each piece (nodes' thread relays carry packets between
// threads this way: a packet costs its sender an enqueue and no wake-up).
//
// Contract:
//  - A producer, on any thread, publishes its work (a release store or
//    stronger), then calls signal(). The first signal after the handler
//    last ran costs a fence and one atomic exchange, and a system call only
//    if the owner's thread sleeps; later ones, until the handler runs, cost
//    a fence and a load.
//  - One process of a FifoScheduler thread attaches a handler (attach(),
//    from that process). The scheduler calls it on that thread at the next
//    switch after a signal, never while the attaching process runs (it
//    drains the work itself before it waits), then clears the mark; a
//    signal that comes after the handler started calls it again. An idle
//    thread that is signalled stops spinning or sleeping. The handler must
//    not block: it may only try_write() (typically a token that wakes the
//    attaching process, which then takes all the work there is).
//  - The deadlock detector counts a marked Arrivals as a process able to
//    run (see Tracker in detail/process.hpp), so work in transit between
//    threads is never mistaken for a deadlock.
//  - detach() (same process, before it ends) stops the calls; signals after
//    it are ignored.
//  - Each Arrivals takes cache lines of its own: the mark is written by the
//    signalling threads and by the owner's, and two threads' Arrivals side
//    by side would send each other's line back and forth too.
//
// Polled sources, the cheaper way (what a busy thread pays nothing for):
//  - A source is a pair of counters, `produced` advanced by one producer
//    (a release store, after the work it counts is written) and `consumed`
//    by the attached process as it takes that work; the source holds work
//    while they differ. They are given to attach() and read by the owner's
//    scheduler at every switch, while it spins, and before it sleeps.
//  - So a producer of a polled source calls poke(), not signal(): no mark,
//    no cache line of the owner's taken, only a look at whether the owner's
//    thread sleeps. That look is ordered after the publish by a fence whose
//    cost the sleeper pays (an asymmetric fence: the OS's membarrier where
//    it has one; a full fence on the producer's side where it does not).
//  - The scheduler calls the handler when a source holds work, once, until
//    the attached process calls taking(), which it does before it takes the
//    sources' work: what comes after that is seen at the next switch.
//  - The deadlock detector counts a source that holds work as a mark.
class alignas(64) Arrivals {
 public:
  struct Source {
    const std::atomic<std::uint64_t>* produced;
    const std::atomic<std::uint64_t>* consumed;
  };

  Arrivals() = default;
  Arrivals(const Arrivals&) = delete;
  Arrivals& operator=(const Arrivals&) = delete;
  ~Arrivals();

  void signal() noexcept;
  // After a publish on one of the polled sources: wakes the owner's thread
  // if it sleeps. Any thread.
  void poke() noexcept;
  // False (nothing attached) if the calling thread's scheduler takes no
  // arrivals (the virtual-time one), or outside a Runtime. `sources` are
  // polled until detach().
  bool attach(std::function<void()> handler, std::vector<Source> sources = {});
  void detach() noexcept;
  // By the attached process, before it takes its sources' work: the
  // handler may be called again for work that comes after.
  void taking() noexcept { handler_outstanding_ = false; }
  // Attached, and signalled since the handler last ran or a source holds work.
  bool pending() const noexcept {
    return scheduler_.load(std::memory_order_seq_cst) != nullptr &&
           (marked_.load(std::memory_order_seq_cst) || polled());
  }

 private:
  friend class FifoScheduler;
  // Work for the handler: a mark (read with `order`), or a source's work it
  // has not been called for. The owner's thread only.
  bool due(std::memory_order order) const noexcept {
    return marked_.load(order) || (!handler_outstanding_ && polled());
  }
  // Some source holds work. Any thread: the sources do not change while attached.
  bool polled() const noexcept {
    for (const Source& s : sources_)
      if (s.produced->load(std::memory_order_acquire) != s.consumed->load(std::memory_order_acquire)) return true;
    return false;
  }
  // Three cache lines: the mark, written by signallers and the owner's
  // thread; what a producer reads, written only at attach and detach; and
  // what the owner's thread alone reads and writes.
  std::atomic<bool> marked_{false};
  alignas(64) std::atomic<FifoScheduler*> scheduler_{nullptr};  // set while attached
  std::vector<Source> sources_;
  alignas(64) bool handler_outstanding_ = false;  // called for a source, taking() not yet
  std::function<void()> handler_;
  boost::fibers::context* owner_ = nullptr;
  void* tracker_ = nullptr;  // the detail::Tracker it is registered with
};

// The default scheduler. Ready fibers run in FIFO order, those of
// high-priority processes before any of low priority (as a transputer runs
// its two priority levels). Among low-priority processes, one woken by a
// communication or a timer runs before those that gave the thread up with
// csp::yield(), so a process that yielded waits as long as woken ones keep
// coming. yield_requested() tells a long computation that asks between
// small steps to yield when a high-priority process is ready or a wake
// from another thread is pending: it gives the thread up for one round and
// goes on, delayed by what is ready, never starved. When none is ready the
// thread first spins for a few microseconds watching for notify() or an
// arrival, then sleeps on a condition variable until notify() or the next
// timer deadline; it does not spin when the runtime has more threads than
// the machine has hardware threads (idle_spin()). Boost's dispatcher fiber
// (which moves timed-out and remotely woken fibers to the ready queue, and
// reads the clock to do so) is kept aside and run at the next switch after
// notify(), after a low-priority process yields, when nothing else is
// ready, or after every `dispatch_period` picks.
class FifoScheduler final : public Scheduler {
 public:
  // `idle`, if given, gathers the time the thread waits with nothing to
  // run; only this thread writes it. `spin`: see idle_spin().
  explicit FifoScheduler(std::chrono::steady_clock::duration* idle = nullptr,
                         std::chrono::microseconds spin = idle_spin(1, 1))
      : spin_limit_(spin), idle_(idle) {}
  // `times`, if given, gathers the thread's running, spinning and sleeping
  // time (see ThreadTimes); the caller starts it.
  FifoScheduler(ThreadTimes* times, std::chrono::microseconds spin) : spin_limit_(spin), times_(times) {}

  void awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept override;
  boost::fibers::context* pick_next() noexcept override;
  bool has_ready_fibers() const noexcept override;
  void suspend_until(std::chrono::steady_clock::time_point const& when) noexcept override;
  void notify() noexcept override;
  // A ready high-priority process, or a wake from another thread not yet
  // dispatched: a packet arrived here that the caller would delay.
  bool yield_requested() const noexcept override;
  bool others_ready() const noexcept override;

 private:
  friend class Arrivals;
  static constexpr unsigned dispatch_period = 32;
  static constexpr int os_yields_before_sleep = 16;

  bool arrival_pending() const noexcept { return arrivals_ && arrivals_->due(std::memory_order_seq_cst); }
  void take_arrivals() noexcept;
  void wake_if_sleeping() noexcept;

  bool take_notification() noexcept;
  bool spin_until_notified(std::chrono::steady_clock::time_point start,
                           std::chrono::steady_clock::time_point when) noexcept;
  bool sleep_until_notified(std::chrono::steady_clock::time_point when) noexcept;

  boost::fibers::scheduler::ready_queue_type ready_;          // high priority, and fibers of no process
  boost::fibers::scheduler::ready_queue_type ready_low_woken_;  // low priority, woken
  boost::fibers::scheduler::ready_queue_type ready_low_;      // low priority, yielded
  boost::fibers::context* dispatcher_ = nullptr;  // set while it is ready
  unsigned picks_since_dispatch_ = 0;
  bool dispatch_soon_ = false;  // a low-priority process yielded since the dispatcher last ran
  std::mutex mutex_;  // orders notify() against the check before sleeping
  std::condition_variable wakeup_;
  // Each on a cache line of its own, apart from what the thread writes at
  // every switch: notified_ is written by other threads, and sleeping_,
  // written only around a sleep, is read by every producer's poke().
  alignas(64) std::atomic<bool> notified_{false};  // a wake from another thread not yet dispatched
  alignas(64) std::atomic<bool> sleeping_{false};  // set under mutex_ while the thread sleeps, or is about to
  alignas(64) const std::chrono::microseconds spin_limit_;
  std::chrono::steady_clock::duration* idle_ = nullptr;
  ThreadTimes* times_ = nullptr;
  Arrivals* arrivals_ = nullptr;  // attached on this thread
};

namespace detail {

// The scheduler of the calling runtime thread, and the csp Scheduler
// installed in it (null on other threads); a runtime thread sets them on
// start and clears them on exit. Cached because context::active() is a
// costly TLS lookup in Boost's shared library, and a thread's scheduler
// never changes.
extern constinit thread_local boost::fibers::scheduler* runtime_scheduler_here;
extern constinit thread_local Scheduler* runtime_algorithm_here;
inline boost::fibers::scheduler* thread_scheduler() { return runtime_scheduler_here; }
inline Scheduler* thread_algorithm() { return runtime_algorithm_here; }
void set_thread_scheduler(boost::fibers::scheduler* s, Scheduler* algorithm);

// The process fiber ctx runs (ctx: the calling fiber's context), from its
// ProcessProps; null outside a Runtime and for fibers of no process.
Process* process_of(boost::fibers::context* ctx);
// The process the calling fiber runs, or null outside a Runtime.
Process* current_process();

// Counted on the thread that wakes: of the processes of other threads it
// woke (detail/wait.hpp), those that found the other thread asleep. Read
// and reset by the runtime thread itself.
extern constinit thread_local std::uint64_t sleepers_woken_here;

// An asymmetric fence for polled Arrivals: a store then a load on each side
// (a producer's publish and its look at whether the owner sleeps; the
// owner's mark that it sleeps and its last poll) are ordered as if both
// used full fences. The light side costs a compiler fence where the OS
// offers membarrier(2), else a full fence; the heavy side the system call
// (a few microseconds), and says false if it could not be sure of the
// pairing (then the sleeper polls). prepare_fences(), called as a Runtime
// is made, starts finding out which the OS offers; until then both sides
// are full fences.
void prepare_fences() noexcept;
bool fences_decided() noexcept;  // prepare_fences() has found out (for tests)
void light_fence() noexcept;
bool heavy_fence() noexcept;

}  // namespace detail

}  // namespace csp
