// SeededScheduler: a uniformly random pick among the ready fibers of the
// highest ready priority, from a seeded splitmix64 sequence.
#include "csp/seeded_scheduler.hpp"

#include <algorithm>
#include <utility>

#include "csp/detail/process.hpp"

namespace csp {

namespace {

constexpr std::uint64_t golden_gamma = 0x9E3779B97F4A7C15u;

// splitmix64's output function.
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
  return z ^ (z >> 31);
}

}  // namespace

std::uint64_t seed_of_stream(std::uint64_t seed, std::uint64_t stream) {
  return stream == 0 ? seed : mix64(seed ^ mix64(stream * golden_gamma));
}

std::uint64_t SeededScheduler::next_random() noexcept {
  state_ += golden_gamma;
  return mix64(state_);
}

// Lemire's multiply-shift on the draw's high 32 bits: exact integer
// arithmetic, so the same index on every platform (ready sets stay far
// below 2^32 fibers).
std::size_t SeededScheduler::below(std::size_t n) noexcept {
  return static_cast<std::size_t>(((next_random() >> 32) * static_cast<std::uint64_t>(n)) >> 32);
}

// A fiber is in one ready set at most once, so room for every fiber in
// each set is room for every awakened().
void SeededScheduler::make_room_for_fiber() {
  Scheduler::make_room_for_fiber();
  const std::size_t needed = fibers_ + 1;
  for (auto* ready : {&high_, &low_})
    if (ready->capacity() < needed) ready->reserve(std::max(needed, 2 * ready->capacity()));
}

boost::fibers::fiber_properties* SeededScheduler::new_properties(boost::fibers::context* ctx) {
  ++fibers_;
  return new ProcessProps(ctx);
}

void SeededScheduler::awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept {
  props.yielded = false;  // a yield is a switch like any other here
  if (ctx->is_context(boost::fibers::type::dispatcher_context)) {
    dispatcher_ = ctx;
  } else if (props.process && props.process->priority == Priority::low) {
    low_.push_back(ctx);  // into the room made for it: cannot throw
  } else {
    high_.push_back(ctx);
  }
}

// A fiber that yields is not among the choices of its own yield (Boost
// re-queues it after the pick), so a yield always switches when another
// fiber is ready. High priority first is a transputer's rule, which
// FifoScheduler keeps too.
boost::fibers::context* SeededScheduler::pick_next() noexcept {
  const bool none_ready = high_.empty() && low_.empty();
  if (dispatcher_ && (none_ready || take_notification() || ++picks_since_dispatch_ >= dispatch_period)) {
    picks_since_dispatch_ = 0;
    return std::exchange(dispatcher_, nullptr);
  }
  if (none_ready) return nullptr;
  std::vector<boost::fibers::context*>* ready = nullptr;
  std::size_t i = 0;
  if (mix_priorities_) {
    i = below(high_.size() + low_.size());
    ready = i < high_.size() ? &high_ : &low_;
    if (ready == &low_) i -= high_.size();
  } else {
    ready = high_.empty() ? &low_ : &high_;
    i = below(ready->size());
  }
  boost::fibers::context* ctx = (*ready)[i];
  (*ready)[i] = ready->back();
  ready->pop_back();
  ++picks_;
  return ctx;
}

bool SeededScheduler::has_ready_fibers() const noexcept { return dispatcher_ || !high_.empty() || !low_.empty(); }

bool SeededScheduler::take_notification() noexcept {
  return notified_.load(std::memory_order_relaxed) && notified_.exchange(false, std::memory_order_acq_rel);
}

void SeededScheduler::suspend_until(std::chrono::steady_clock::time_point const& when) noexcept {
  std::unique_lock<std::mutex> lk(mutex_);
  const auto woken = [this] { return notified_.load(std::memory_order_relaxed); };
  if (when == std::chrono::steady_clock::time_point::max()) {
    wakeup_.wait(lk, woken);
  } else {
    wakeup_.wait_until(lk, when, woken);
  }
  notified_.store(false, std::memory_order_relaxed);
}

void SeededScheduler::notify() noexcept {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    notified_.store(true, std::memory_order_release);
  }
  wakeup_.notify_one();
}

SchedulerFactory seeded_scheduler(std::uint64_t seed, bool mix_priorities) {
  return [seed, mix_priorities](unsigned thread) -> Scheduler* {
    return new SeededScheduler(seed_of_stream(seed, thread), mix_priorities);
  };
}

}  // namespace csp
