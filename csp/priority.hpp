// A csp process's priority, one of a transputer's two levels; a plain type
// of its own so that the process records (detail/process.hpp) and the
// schedulers (scheduler.hpp) both name it without naming each other.
#pragma once

namespace csp {

// A transputer's two levels. A ready high-priority process always runs
// before a ready low-priority one of the same thread; neither preempts the
// running process, so a low-priority process that computes for long offers
// the thread now and then with csp::yield() (runtime.hpp), as the
// transputer time-slices its low-priority processes. The virtual-time
// scheduler (virtual_time.hpp) orders by clock alone.
enum class Priority { high, low };

}  // namespace csp
