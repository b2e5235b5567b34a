// FifoScheduler: FIFO ready queues, high priority first, then woken low
// priority, then yielded; when idle, a short spin, then a sleep.
#include "csp/scheduler.hpp"

#include <mutex>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>

#ifdef __linux__
#include <linux/membarrier.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <boost/fiber/detail/cpu_relax.hpp>

#include "csp/detail/process.hpp"

namespace csp {

namespace {
// A plain pointer: a thread_local with a destructor would need memory of its own.
thread_local void* properties_reserve = nullptr;
}  // namespace

constinit thread_local std::uint64_t detail::sleepers_woken_here = 0;

namespace {
// The fences' mode, decided once a process. Registering for membarrier(2)'s
// private expedited command waits for the OS (some 10 ms), so a thread of
// its own does it while the runtime goes on with full fences; the mode then
// leaves `pending` once. A sleeper that saw `pending` cannot know which side
// a producer took, so it bounds its sleep (see sleep_until_notified).
enum class FenceMode : int { pending, asymmetric, symmetric };
std::atomic<FenceMode> fence_mode{FenceMode::pending};

bool register_membarrier() noexcept {
#ifdef __linux__
  const long commands = ::syscall(SYS_membarrier, MEMBARRIER_CMD_QUERY, 0, 0);
  return commands > 0 && (commands & MEMBARRIER_CMD_PRIVATE_EXPEDITED) &&
         ::syscall(SYS_membarrier, MEMBARRIER_CMD_REGISTER_PRIVATE_EXPEDITED, 0, 0) == 0;
#else
  return false;
#endif
}
}  // namespace

void detail::prepare_fences() noexcept {
  static std::once_flag once;
  std::call_once(once, [] {
    try {
      std::thread([] {
        fence_mode.store(register_membarrier() ? FenceMode::asymmetric : FenceMode::symmetric);
      }).detach();
    } catch (const std::system_error&) {
      fence_mode.store(FenceMode::symmetric);
    }
  });
}

bool detail::fences_decided() noexcept { return fence_mode.load() != FenceMode::pending; }

void detail::light_fence() noexcept {
  if (fence_mode.load(std::memory_order_relaxed) == FenceMode::asymmetric) {
    std::atomic_signal_fence(std::memory_order_seq_cst);
  } else {
    std::atomic_thread_fence(std::memory_order_seq_cst);
  }
}

// A full barrier here, and on every running thread of the process where
// the producers may take the light side. False when it cannot be sure the
// two sides paired: the mode was still pending, or the call failed.
bool detail::heavy_fence() noexcept {
  std::atomic_thread_fence(std::memory_order_seq_cst);
  switch (fence_mode.load(std::memory_order_seq_cst)) {
    case FenceMode::symmetric:
      return true;
    case FenceMode::asymmetric:
#ifdef __linux__
      return ::syscall(SYS_membarrier, MEMBARRIER_CMD_PRIVATE_EXPEDITED, 0, 0) == 0;
#endif
    case FenceMode::pending:
      break;
  }
  return false;
}
constinit thread_local boost::fibers::scheduler* detail::runtime_scheduler_here = nullptr;
constinit thread_local Scheduler* detail::runtime_algorithm_here = nullptr;

void detail::set_thread_scheduler(boost::fibers::scheduler* s, Scheduler* algorithm) {
  runtime_scheduler_here = s;
  runtime_algorithm_here = algorithm;
}

detail::Process* detail::process_of(boost::fibers::context* ctx) {
  if (!runtime_scheduler_here) return nullptr;
  auto* props = ctx->get_properties();
  return props ? static_cast<ProcessProps*>(props)->process : nullptr;
}

detail::Process* detail::current_process() {
  if (!runtime_scheduler_here) return nullptr;
  return process_of(boost::fibers::context::active());
}

static_assert(sizeof(ProcessProps) <= ProcessProps::reserve_bytes);

void* ProcessProps::operator new(std::size_t size) {
  if (properties_reserve && size <= reserve_bytes) return std::exchange(properties_reserve, nullptr);
  return ::operator new(size);
}

void ProcessProps::operator delete(void* p) noexcept { ::operator delete(p); }

void detail::reserve_properties() {
  if (!properties_reserve) properties_reserve = ::operator new(ProcessProps::reserve_bytes);
}

void Scheduler::make_room_for_fiber() { detail::reserve_properties(); }

void detail::release_properties_reserve() noexcept { ::operator delete(std::exchange(properties_reserve, nullptr)); }

// With more threads than hardware threads a spinning thread would take the
// core from one that has work, so it does not spin.
std::chrono::microseconds idle_spin(unsigned threads, unsigned hardware_threads) {
  if (hardware_threads != 0 && threads > hardware_threads) return std::chrono::microseconds{0};
  return std::chrono::microseconds{50};
}

// A process's fiber is bound to its record when it first runs, so its first
// wake-up, at spawn, takes the high-priority queue.
// Woken low-priority processes go before yielded ones: a process that waited
// on a message has little left to do before it waits again, and the ones
// that yielded are the long computations it would otherwise queue behind.
// A process of either priority that yields to all goes behind every one.
// A low-priority process that yields to urgent work goes ahead of every
// other of its priority (the front of the woken ones), behind the
// high-priority ones (a wake from another thread has the dispatcher run
// first, so it is among those).
void FifoScheduler::awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept {
  const bool yielded = std::exchange(props.yielded, false);
  const bool ahead = std::exchange(props.ahead, false);
  if (ctx->is_context(boost::fibers::type::dispatcher_context)) {
    dispatcher_ = ctx;
  } else if (std::exchange(props.behind_all, false)) {
    ctx->ready_link(ready_low_);
    dispatch_soon_ = true;
  } else if (ahead && props.process && props.process->priority == Priority::low) {
    ready_low_woken_.push_front(*ctx);
  } else if (props.process && props.process->priority == Priority::low) {
    ctx->ready_link(yielded ? ready_low_ : ready_low_woken_);
    // A long computation offers the thread: timers due meanwhile go first.
    dispatch_soon_ = dispatch_soon_ || yielded;
  } else {
    ctx->ready_link(ready_);
  }
}

// Runs the arrivals handler, unless its own process is the one switching
// away (it takes the work itself before it waits). The handler first, then
// the clear: the process it wakes runs after this switch, so it takes
// whatever came before the clear, and whatever comes after marks again.
void FifoScheduler::take_arrivals() noexcept {
  if (boost::fibers::context::active() == arrivals_->owner_) return;
  arrivals_->handler_();
  arrivals_->handler_outstanding_ = true;
  // Cleared only if set: a store would take the line from the signallers.
  if (arrivals_->marked_.load(std::memory_order_relaxed)) arrivals_->marked_.store(false, std::memory_order_seq_cst);
}

// The dispatcher is kept aside rather than queued with the others: so a
// process woken from another thread waits for one switch, not for a round
// of the queue, a timer that fell due during a long computation fires when
// the computation offers the thread, and most switches read no clock.
boost::fibers::context* FifoScheduler::pick_next() noexcept {
  if (arrivals_ && arrivals_->due(std::memory_order_relaxed)) take_arrivals();
  const bool none_ready = ready_.empty() && ready_low_woken_.empty() && ready_low_.empty();
  if (dispatcher_ && (none_ready || take_notification() || std::exchange(dispatch_soon_, false) ||
                      ++picks_since_dispatch_ >= dispatch_period)) {
    picks_since_dispatch_ = 0;
    return std::exchange(dispatcher_, nullptr);
  }
  if (none_ready) return nullptr;
  auto& queue = !ready_.empty() ? ready_ : !ready_low_woken_.empty() ? ready_low_woken_ : ready_low_;
  boost::fibers::context* ctx = &queue.front();
  queue.pop_front();
  return ctx;
}

bool FifoScheduler::has_ready_fibers() const noexcept {
  return dispatcher_ || !ready_.empty() || !ready_low_woken_.empty() || !ready_low_.empty();
}

// Claims a pending notify(). Boost queues a remotely woken fiber before it
// notifies, and the dispatcher that runs next moves it to a ready queue.
// Reads before it claims, like the spin below.
bool FifoScheduler::take_notification() noexcept {
  return notified_.load(std::memory_order_relaxed) && notified_.exchange(false, std::memory_order_acq_rel);
}

// Spins, from `start`, until notified (true), the spin limit or `when`,
// whichever first; with no spin limit, looks once. The spin comes first
// because waking a sleeping thread costs a system call on both sides,
// several times a message's own cost.
// Reads before it claims, so the spinning thread does not keep taking the
// flag's cache line from the notifier.
bool FifoScheduler::spin_until_notified(std::chrono::steady_clock::time_point start,
                                        std::chrono::steady_clock::time_point when) noexcept {
  if (spin_limit_.count() == 0) {
    for (int i = 0; i < os_yields_before_sleep; ++i) {
      if (take_notification() || arrival_pending()) return true;
      std::this_thread::yield();
    }
    return take_notification() || arrival_pending();
  }
  const auto end = std::min(when, start + spin_limit_);
  do {
    for (int i = 0; i < 64; ++i) {
      if (take_notification() || arrival_pending()) return true;
      cpu_relax();  // Boost.Fiber's spin-wait hint for this architecture
    }
  } while (std::chrono::steady_clock::now() < end);
  return false;
}

// Sleeps until notified or `when`; true if notified. sleeping_ tells
// notify() that its wake finds the thread asleep (for the accounts).
bool FifoScheduler::sleep_until_notified(std::chrono::steady_clock::time_point when) noexcept {
  std::unique_lock<std::mutex> lk(mutex_);
  sleeping_.store(true, std::memory_order_seq_cst);
  // A producer of a polled source publishes, then looks at sleeping_ with
  // only the light side of the fence between: this side's heavy one makes
  // either that look see the store above or the check below see the work.
  // Where it cannot be sure (the fences' mode not yet decided, or a failed
  // membarrier), the sleep is cut to a poll's period.
  auto until = when;
  if (arrivals_ && !arrivals_->sources_.empty() && !detail::heavy_fence())
    until = std::min(when, std::chrono::steady_clock::now() + std::chrono::milliseconds(1));
  const auto woken = [this] { return notified_.load(std::memory_order_seq_cst) || arrival_pending(); };
  bool notified = true;
  if (until == std::chrono::steady_clock::time_point::max()) {
    wakeup_.wait(lk, woken);
  } else {
    notified = wakeup_.wait_until(lk, until, woken);
  }
  sleeping_.store(false, std::memory_order_relaxed);
  notified_.store(false, std::memory_order_relaxed);
  return notified;
}

// The clock readings here are the ones the wait needs (the spin deadline,
// the end of the spin); the accounts add one at the end of a sleep.
void FifoScheduler::suspend_until(std::chrono::steady_clock::time_point const& when) noexcept {
  const auto start = std::chrono::steady_clock::now();
  if (times_) {
    times_->close(start);
    ++times_->waits;
  }
  // Notified, or the deadline passed while spinning: nothing to sleep for.
  if (spin_until_notified(start, when) || std::chrono::steady_clock::now() >= when) {
    if (!times_ && !idle_) return;
    const auto end = std::chrono::steady_clock::now();
    if (idle_) *idle_ += end - start;
    if (times_) times_->spinning += end - start, times_->awake_since = end;
    return;
  }
  const auto slept = std::chrono::steady_clock::now();
  sleep_until_notified(when);
  if (!times_ && !idle_) return;
  const auto end = std::chrono::steady_clock::now();
  if (idle_) *idle_ += end - start;
  if (times_) {
    times_->spinning += slept - start;
    times_->sleeping += end - slept;
    ++times_->sleeps;
    times_->awake_since = end;
  }
}

void FifoScheduler::notify() noexcept {
  if (sleeping_.load(std::memory_order_relaxed)) ++detail::sleepers_woken_here;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    notified_.store(true, std::memory_order_release);
  }
  wakeup_.notify_one();
}

bool FifoScheduler::yield_requested() const noexcept {
  return notified_.load(std::memory_order_relaxed) || !ready_.empty() ||
         (arrivals_ && arrivals_->due(std::memory_order_relaxed));
}

bool FifoScheduler::others_ready() const noexcept {
  return !ready_.empty() || !ready_low_woken_.empty() || !ready_low_.empty();
}

// sleeping_ is set (seq_cst) before the sleeper looks at its arrivals for
// the last time, and signal() marks (seq_cst) before it reads sleeping_:
// either the sleeper sees the mark or the signaller sees it asleep.
void FifoScheduler::wake_if_sleeping() noexcept {
  if (sleeping_.load(std::memory_order_seq_cst)) notify();
}

Arrivals::~Arrivals() { detach(); }

// The fence keeps the producer's publish ahead of the read of the mark. A
// mark read as set may be one the scheduler is clearing after its handler
// ran (take_arrivals: handler, then the clear); the handler's process then
// takes the work after the clear, and sees it only if the publish was
// visible before the mark was read. Without the fence a store may wait in
// its core past a later load (x86 keeps stores in order with each other,
// not with loads): the read found the old mark, the clear came, the
// process took the ring as it was, and the work stayed there unsignalled.
void Arrivals::signal() noexcept {
  std::atomic_thread_fence(std::memory_order_seq_cst);
  if (marked_.load(std::memory_order_relaxed) || marked_.exchange(true, std::memory_order_seq_cst)) return;
  if (FifoScheduler* s = scheduler_.load(std::memory_order_seq_cst)) s->wake_if_sleeping();
}

// The light side of the asymmetric fence (see sleep_until_notified). A
// sleeper already notified is not notified again: it wakes, and polls
// until it next sleeps, when its heavy fence shows it this publish.
void Arrivals::poke() noexcept {
  detail::light_fence();
  if (FifoScheduler* s = scheduler_.load(std::memory_order_relaxed);
      s && s->sleeping_.load(std::memory_order_relaxed) && !s->notified_.load(std::memory_order_relaxed))
    s->notify();
}

bool Arrivals::attach(std::function<void()> handler, std::vector<Source> sources) {
  auto* s = dynamic_cast<FifoScheduler*>(detail::thread_algorithm());
  detail::Process* p = detail::current_process();
  if (!s || !p || !p->tracker) return false;
  if (s->arrivals_) throw std::logic_error("csp: a runtime thread takes one Arrivals at a time");
  handler_ = std::move(handler);
  sources_ = std::move(sources);
  handler_outstanding_ = false;
  owner_ = boost::fibers::context::active();
  s->arrivals_ = this;
  p->tracker->watch(p->thread, this);
  tracker_ = p->tracker;
  scheduler_.store(s, std::memory_order_seq_cst);
  return true;
}

void Arrivals::detach() noexcept {
  FifoScheduler* s = scheduler_.exchange(nullptr, std::memory_order_seq_cst);
  if (!s) return;
  s->arrivals_ = nullptr;
  static_cast<detail::Tracker*>(tracker_)->unwatch(this);
  marked_.store(false, std::memory_order_seq_cst);
}

}  // namespace csp
