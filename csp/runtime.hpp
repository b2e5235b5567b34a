// Runtime: places processes (fibers) on OS threads and runs them to the end.
//
// Each of the T threads has its own Scheduler (made by the factory in
// RuntimeOptions); a process stays on the thread it was placed on. A thread
// with nothing ready sleeps in its scheduler until another thread wakes one
// of its fibers or a timer is due. run() ends when the last process ends, or
// reports a deadlock once every live process waits on a channel with no timer
// pending — after unwinding them all. par() is occam PAR inside a process.
// Blocking on a channel (a read, write, ALT or timed read that must wait) is
// for processes: a thread outside any Runtime that would block gets
// std::logic_error instead of a wait nothing may end. It may still use
// channels without blocking, and run processes with par(), whose children
// may block. Who wakes whom: spawn() wakes the target thread's main fiber (it
// waits on an inbox of new processes); the last process to end wakes every
// thread's main fiber, which then joins its fibers and returns.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "csp/scheduler.hpp"

namespace csp {

// How one runtime thread spent a run. Under the default scheduler, seconds
// = running + spinning + sleeping (to the clock's resolution): running is
// the time it ran processes (and switched between them), spinning the time
// it watched for a wake with nothing to run, sleeping the time it slept in
// the OS. cpu_seconds is what the OS charged the thread: running plus
// spinning less the time the OS gave its core to another thread (more
// threads than cores, or a busy machine). Under other schedulers only
// seconds and cpu_seconds are kept.
struct ThreadUse {
  double seconds = 0;       // from its start until its last process ended
  double idle_seconds = 0;  // spinning + sleeping: waiting with no process ready
  double running_seconds = 0;
  double spinning_seconds = 0;
  double sleeping_seconds = 0;
  double cpu_seconds = 0;   // the thread's CPU time over the same span
  std::uint64_t waits = 0;  // times it ran out of processes to run
  std::uint64_t sleeps = 0; // of which it spun in vain and slept in the OS
  std::uint64_t remote_wakes = 0;    // processes of other threads it woke
  // Times it woke another thread from sleep, a system call each: for a
  // process it woke there, or for a relay's signal (Arrivals::signal), so
  // at most remote_wakes plus the signals its relay gave.
  std::uint64_t sleepers_woken = 0;
};

struct RuntimeOptions {
  unsigned threads = 0;                   // 0: std::thread::hardware_concurrency()
  std::size_t stack_size = 256 * 1024;    // bytes per process fiber, with a guard page below (detail/stack.hpp)
  SchedulerFactory scheduler;             // empty: FifoScheduler on every thread
  // Other processes of this program share the cores (more of them than
  // cores): an idle thread of the default scheduler sleeps at once rather
  // than spin for a wake, which would take the core from one with work.
  bool shared_cores = false;
  // Called on the failing process's thread, after it ended with an
  // exception other than Poisoned and before run() returns: lets a program
  // whose other processes wait on something outside the runtime (a wire to
  // another OS process) stop them. Must not block; what it throws is dropped.
  std::function<void(const std::string& process, std::exception_ptr error)> on_failure;
};

class Runtime {
 public:
  explicit Runtime(unsigned threads = 0);
  explicit Runtime(RuntimeOptions options);
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  unsigned threads() const;
  // Before run(), or from inside a running process. thread is taken modulo threads().
  void spawn(std::string name, unsigned thread, std::function<void()> body, Priority priority = Priority::high);
  // Runs every process to its end; once per Runtime. Rethrows a process's
  // exception (ProcessesFailed if several failed), also when the others
  // then deadlocked waiting for it; Poisoned ends a process normally.
  // Throws Deadlock listing the blocked processes; ProcessNotStarted if a
  // process had no memory for its stack or scheduling record (those
  // waiting for it unwound as in a deadlock); std::runtime_error, before any
  // process starts, if a runtime thread cannot be created or set up.
  void run();
  // After run(): one entry per thread.
  std::vector<ThreadUse> thread_use() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// PAR: runs every process as a fiber on the calling thread and waits for all.
// Rethrows the first failure after all have ended (ProcessesFailed if several).
// Called from a thread outside any Runtime, it runs as process "par" of a
// Runtime of one thread of its own, and waits for it: a deadlock among its
// children is then thrown as Deadlock.
void par(std::vector<std::function<void()>> processes);

// Fiber-aware sleep; never counted as blocked by the deadlock detector.
void sleep_for(std::chrono::steady_clock::duration d);

// Puts the caller at the back of its thread's ready queue, so that the
// processes ready before it run first (FifoScheduler: a low-priority caller
// lets every ready high-priority process run, every woken low-priority one,
// and the ones that yielded before it). Never counted as blocked.
void yield();

// Puts the caller, whatever its priority, behind every process of its
// thread ready now (FifoScheduler: at the back of the yielded low-priority
// ones) and returns true once it runs again; returns false at once if no
// other process is ready, or under a scheduler without the rule (virtual
// time). A process that gathers work for one costly transfer lets the
// thread's pass add to it so, and sends when the thread would otherwise
// wait. Never counted as blocked.
bool yield_to_all();

// Lets the work that yield_requested() reports run, then goes on ahead of
// every other low-priority process (FifoScheduler: the ready high-priority
// processes and the wakes from other threads run, and the caller resumes
// before the low-priority processes that were or became ready meanwhile);
// yield() under schedulers without the rule. A long low-priority
// computation that asks between small steps so answers a packet for its
// thread within a step, without handing its turn to the thread's other
// computations. Never counted as blocked.
void yield_to_urgent();

// True if the calling thread has work that should not wait for the caller
// to finish a long computation: under FifoScheduler, a ready high-priority
// process, or a process woken from another thread and not yet dispatched
// (a packet arrived for it). A few loads and no clock, so a computation
// may ask between small steps and yield() only when told; false outside a
// Runtime and under schedulers without the rule (virtual time).
bool yield_requested();

// Name of the calling process ("" outside a Runtime).
const std::string& current_process_name();

}  // namespace csp
