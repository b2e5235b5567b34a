// Virtual time: run a csp program as a discrete-event simulation whose
// processes are the real fibers, so it reports what the run would take on a
// machine with given costs, whatever the host's speed (the model and why it
// holds: docs/architecture.md, "Virtual time").
//
// A process spends virtual time only by this_process::advance(d) (delay(d)
// does the same here; csp::sleep_for always sleeps in wall time); a channel
// operation takes none. VirtualTimeScheduler resumes the ready fiber with the
// smallest key, FIFO among equals: advance(d) keys it at clock + d, a wake by
// another fiber at max(own clock, waker's clock), and on resumption its clock
// becomes its key. Invariant: the running fiber's clock is the smallest key
// of all that can run, and never decreases. Determinism needs ONE runtime
// thread (RuntimeOptions{.threads = 1}) and no wall-clock timers (read_for and
// read_until deadlines, ALT timeouts, sleep_for): its programs use none.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <tuple>
#include <vector>

#include "csp/scheduler.hpp"

namespace csp {

// Picoseconds: a 64-bit count covers 106 days at sub-nanosecond resolution.
using VirtualDuration = std::chrono::duration<std::int64_t, std::pico>;

class VirtualTimeScheduler;

// Per-fiber state of the virtual-time scheduler.
class VirtualProps final : public ProcessProps {
 public:
  VirtualProps(boost::fibers::context* ctx, VirtualTimeScheduler& scheduler)
      : ProcessProps(ctx, true), scheduler(scheduler) {}
  boost::fibers::context* fiber() const { return ctx_; }
  VirtualTimeScheduler& scheduler;  // of the fiber's thread
  VirtualDuration clock{0};         // the fiber's virtual time: "now" while it runs
  bool queued = false;              // put in the ready set by pass_to(): skip the next awakened()
};

// The largest virtual time a run reached; read after Runtime::run().
struct VirtualTimeRecord {
  std::atomic<std::int64_t> end_ps{0};
  VirtualDuration end() const { return VirtualDuration(end_ps.load()); }
};

class VirtualTimeScheduler final : public Scheduler {
 public:
  // Made on the runtime thread it schedules, which it marks as keeping virtual time.
  explicit VirtualTimeScheduler(std::shared_ptr<VirtualTimeRecord> record = {});
  ~VirtualTimeScheduler() override;

  void make_room_for_fiber() override;
  boost::fibers::fiber_properties* new_properties(boost::fibers::context* ctx) override;
  void awakened(boost::fibers::context* ctx, ProcessProps& props) noexcept override;
  boost::fibers::context* pick_next() noexcept override;
  bool has_ready_fibers() const noexcept override;
  void suspend_until(std::chrono::steady_clock::time_point const& when) noexcept override;
  void notify() noexcept override;

  // The running fiber self moves its clock to `until`: it keeps running if no
  // other fiber is due before (or, at equal time, was ready first); otherwise
  // it joins the ready set at `until` and yields. (Boost.Fiber picks the next
  // fiber before it re-queues a yielding one, so the yielder queues itself.)
  void pass_to(boost::fibers::context* self, VirtualProps& props, VirtualDuration until);

  // The running fiber's properties (null before the first pick).
  VirtualProps* running() const { return running_; }

 private:
  void note_time(std::int64_t t);

  // Ready fibers: the smallest key first, FIFO among equal keys. A fiber
  // ready at the current time `now_` (woken, or passing at zero cost) joins
  // the FIFO `current_`; one ready later joins the heap `later_` of
  // (key, arrival, fiber). Among equal keys the heap's entries came first:
  // `now_` moves on only when `current_` is empty, so whatever the heap holds
  // at the new `now_` was queued before anything `current_` gets.
  using Entry = std::tuple<std::int64_t, std::uint64_t, boost::fibers::context*>;
  struct RunsLater;  // the heap's order
  void push(std::int64_t key, boost::fibers::context* ctx);
  boost::fibers::scheduler::ready_queue_type current_;
  std::vector<Entry> later_;  // a heap in a vector, with room for every fiber (make_room_for_fiber)
  std::size_t fibers_ = 0;    // fibers given properties: a bound on those in later_
  std::int64_t now_ = 0;      // the largest key picked yet: the current virtual time
  // The properties of the fiber picked last, which is the running fiber
  // (Boost resumes what pick_next returns), or null before the first pick.
  VirtualProps* running_ = nullptr;
  std::uint64_t arrivals_ = 0;
  // Boost's dispatcher fiber, kept aside while it is ready and run when no
  // process is or after every dispatch_period picks (it frees finished
  // fibers; a single-thread virtual-time program has no timers or
  // cross-thread wakes for it to deliver), so it takes no place in the time
  // order and costs no clock read per switch.
  static constexpr unsigned dispatch_period = 64;
  boost::fibers::context* dispatcher_ = nullptr;
  unsigned picks_since_dispatch_ = 0;
  std::shared_ptr<VirtualTimeRecord> record_;
  std::mutex mutex_;  // guards notified_ for the sleeping thread
  std::condition_variable wakeup_;
  bool notified_ = false;
};

// A factory for RuntimeOptions::scheduler; record (optional) receives the end time.
SchedulerFactory virtual_time_scheduler(std::shared_ptr<VirtualTimeRecord> record = {});

namespace this_process {

// True when the calling fiber runs under a VirtualTimeScheduler.
bool in_virtual_time();
// The calling fiber's virtual clock (zero outside virtual time).
VirtualDuration now();
// Spends d of virtual time: clock += d, then every fiber due earlier runs
// first. Outside virtual time it does nothing. d must not be negative.
void advance(VirtualDuration d);
// Lets every ready fiber due no later than now run first (a yield in virtual
// time; nothing outside it).
void sync();
// Spends d: virtual time under a VirtualTimeScheduler, a real sleep otherwise.
void delay(std::chrono::nanoseconds d);

}  // namespace this_process

}  // namespace csp
