// Exceptions of the CSP runtime.
// Poisoned ends a process normally (it is how a network shuts down); Deadlock,
// ProcessesFailed and ProcessNotStarted are what Runtime::run() reports when
// a run goes wrong.
#pragma once

#include <stdexcept>
#include <string>

namespace csp {

// Thrown by every blocking or try operation on a poisoned channel.
struct Poisoned : std::runtime_error {
  explicit Poisoned(const std::string& channel)
      : std::runtime_error("channel '" + channel + "' is poisoned") {}
};

// Thrown by Runtime::run() when every live process waits on a channel and no
// timer is pending; what() lists each blocked process and what it waits on.
// If a process had failed, its failure is reported instead (the others were
// most likely waiting for it).
struct Deadlock : std::runtime_error {
  explicit Deadlock(const std::string& dump) : std::runtime_error(dump) {}
};

// Thrown by Runtime::run() and par() when more than one process failed;
// what() holds the first failure, then the next few and how many more.
struct ProcessesFailed : std::runtime_error {
  explicit ProcessesFailed(const std::string& summary) : std::runtime_error(summary) {}
};

// Thrown by Runtime::run() when a spawned process could not start (no
// memory for its stack or its scheduling record), and by par() for a child
// that could not: what() names the first and counts the others. The
// processes that waited for it were unwound, as in a deadlock, which this
// error reports in its place, being the cause.
struct ProcessNotStarted : std::runtime_error {
  explicit ProcessNotStarted(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace csp
