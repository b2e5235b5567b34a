// FifoScheduler: FIFO ready queue; sleeps on a condition variable when idle.
#include "csp/scheduler.hpp"

#include <utility>

namespace csp {

void FifoScheduler::awakened(boost::fibers::context* ctx, ProcessProps&) noexcept {
  if (ctx->is_context(boost::fibers::type::dispatcher_context)) {
    dispatcher_ = ctx;
  } else {
    ctx->ready_link(ready_);
  }
}

boost::fibers::context* FifoScheduler::pick_next() noexcept {
  if (dispatcher_ && (ready_.empty() || ++picks_since_dispatch_ >= dispatch_period)) {
    picks_since_dispatch_ = 0;
    return std::exchange(dispatcher_, nullptr);
  }
  if (ready_.empty()) return nullptr;
  boost::fibers::context* ctx = &ready_.front();
  ready_.pop_front();
  return ctx;
}

bool FifoScheduler::has_ready_fibers() const noexcept { return dispatcher_ || !ready_.empty(); }

void FifoScheduler::suspend_until(std::chrono::steady_clock::time_point const& when) noexcept {
  std::unique_lock<std::mutex> lk(mutex_);
  const auto woken = [this] { return notified_; };
  if (when == std::chrono::steady_clock::time_point::max()) {
    wakeup_.wait(lk, woken);
  } else {
    wakeup_.wait_until(lk, when, woken);
  }
  notified_ = false;
}

void FifoScheduler::notify() noexcept {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    notified_ = true;
  }
  wakeup_.notify_one();
}

}  // namespace csp
