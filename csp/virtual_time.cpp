// VirtualTimeScheduler and the this_process clock API (see virtual_time.hpp).
#include "csp/virtual_time.hpp"

#include "csp/detail/process.hpp"
#include "csp/runtime.hpp"

#include <algorithm>
#include <utility>
#include <boost/fiber/operations.hpp>
#include <stdexcept>

namespace csp {

static_assert(sizeof(VirtualProps) <= ProcessProps::reserve_bytes);

namespace {

// Every fiber of a runtime thread has ProcessProps (scheduler.hpp).
VirtualProps* props_of(boost::fibers::context* ctx) {
  if (!ctx || !detail::thread_scheduler()) return nullptr;
  auto* props = static_cast<ProcessProps*>(ctx->get_properties());
  return props && props->virtual_time ? static_cast<VirtualProps*>(props) : nullptr;
}

// The scheduler of this thread, if it keeps virtual time.
thread_local VirtualTimeScheduler* thread_clock = nullptr;

// The calling fiber's properties, if it runs in virtual time.
VirtualProps* running_props() { return thread_clock ? thread_clock->running() : nullptr; }

}  // namespace

// Heap order: the entry that runs later sinks (std heaps keep the largest on top).
struct VirtualTimeScheduler::RunsLater {
  bool operator()(const Entry& a, const Entry& b) const {
    return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) > std::get<0>(b) : std::get<1>(a) > std::get<1>(b);
  }
};

VirtualTimeScheduler::VirtualTimeScheduler(std::shared_ptr<VirtualTimeRecord> record)
    : record_(record ? std::move(record) : std::make_shared<VirtualTimeRecord>()) {
  thread_clock = this;
}

VirtualTimeScheduler::~VirtualTimeScheduler() {
  if (thread_clock == this) thread_clock = nullptr;
}

// A fiber is in later_ at most once, so room for one entry per fiber is
// room for every push.
void VirtualTimeScheduler::make_room_for_fiber() {
  Scheduler::make_room_for_fiber();
  const std::size_t needed = fibers_ + 1;
  if (later_.capacity() < needed) later_.reserve(std::max(needed, 2 * later_.capacity()));
}

boost::fibers::fiber_properties* VirtualTimeScheduler::new_properties(boost::fibers::context* ctx) {
  ++fibers_;
  return new VirtualProps(ctx, *this);
}

void VirtualTimeScheduler::push(std::int64_t key, boost::fibers::context* ctx) {
  if (key == now_) {
    ctx->ready_link(current_);
    return;
  }
  later_.emplace_back(key, arrivals_++, ctx);
  std::push_heap(later_.begin(), later_.end(), RunsLater{});
}

void VirtualTimeScheduler::awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept {
  if (ctx->is_context(boost::fibers::type::dispatcher_context)) {
    dispatcher_ = ctx;
    return;
  }
  auto& self = static_cast<VirtualProps&>(props);
  if (self.queued) {  // pass_to() has queued it already, at its own time
    self.queued = false;
    return;
  }
  // Woken by the running fiber (a channel, an ALT, a PAR's end): no earlier
  // than the waker's now.
  const VirtualProps* waker = running_;
  const VirtualDuration key = std::max(self.clock, waker ? waker->clock : self.clock);
  push(key.count(), ctx);
}

void VirtualTimeScheduler::pass_to(boost::fibers::context* self, VirtualProps& props, VirtualDuration until) {
  if (current_.empty() && (later_.empty() || std::get<0>(later_.front()) > until.count())) {
    props.clock = until;
    note_time(until.count());
    return;
  }
  props.queued = true;
  push(until.count(), self);
  boost::this_fiber::yield();
}

void VirtualTimeScheduler::note_time(std::int64_t t) {
  if (t > record_->end_ps.load(std::memory_order_relaxed)) record_->end_ps.store(t, std::memory_order_relaxed);
}

boost::fibers::context* VirtualTimeScheduler::pick_next() noexcept {
  const bool none_ready = current_.empty() && later_.empty();
  if (dispatcher_ && (none_ready || ++picks_since_dispatch_ >= dispatch_period)) {
    picks_since_dispatch_ = 0;
    running_ = props_of(dispatcher_);
    if (running_) running_->clock = VirtualDuration(now_);  // what it wakes, it wakes now
    return std::exchange(dispatcher_, nullptr);
  }
  if (none_ready) return nullptr;
  std::int64_t key = now_;
  boost::fibers::context* ctx = nullptr;
  if (!later_.empty() && (current_.empty() || std::get<0>(later_.front()) <= now_)) {
    std::pop_heap(later_.begin(), later_.end(), RunsLater{});
    key = std::get<0>(later_.back());
    ctx = std::get<2>(later_.back());
    later_.pop_back();
  } else {
    ctx = &current_.front();
    current_.pop_front();
  }
  now_ = std::max(now_, key);
  running_ = props_of(ctx);
  if (running_) running_->clock = VirtualDuration(key);
  note_time(key);
  return ctx;
}

bool VirtualTimeScheduler::has_ready_fibers() const noexcept {
  return dispatcher_ || !current_.empty() || !later_.empty();
}

void VirtualTimeScheduler::suspend_until(std::chrono::steady_clock::time_point const& when) noexcept {
  std::unique_lock<std::mutex> lk(mutex_);
  const auto woken = [this] { return notified_; };
  if (when == std::chrono::steady_clock::time_point::max()) {
    wakeup_.wait(lk, woken);
  } else {
    wakeup_.wait_until(lk, when, woken);
  }
  notified_ = false;
}

void VirtualTimeScheduler::notify() noexcept {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    notified_ = true;
  }
  wakeup_.notify_one();
}

SchedulerFactory virtual_time_scheduler(std::shared_ptr<VirtualTimeRecord> record) {
  return [record](unsigned) -> Scheduler* { return new VirtualTimeScheduler(record); };
}

namespace this_process {

bool in_virtual_time() { return running_props() != nullptr; }

VirtualDuration now() {
  const VirtualProps* p = running_props();
  return p ? p->clock : VirtualDuration{0};
}

void advance(VirtualDuration d) {
  if (d.count() < 0) throw std::invalid_argument("csp::this_process::advance: negative duration");
  if (VirtualProps* p = running_props()) p->scheduler.pass_to(p->fiber(), *p, p->clock + d);
}

void sync() {
  if (VirtualProps* p = running_props()) p->scheduler.pass_to(p->fiber(), *p, p->clock);
}

void delay(std::chrono::nanoseconds d) {
  if (in_virtual_time()) {
    advance(d);
  } else {
    sleep_for(d);
  }
}

}  // namespace this_process

}  // namespace csp
