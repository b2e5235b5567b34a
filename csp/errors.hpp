// Exceptions of the CSP runtime.
// Poisoned ends a process normally (it is how a network shuts down); Deadlock
// and ProcessesFailed are what Runtime::run() reports when a run goes wrong.
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
struct Deadlock : std::runtime_error {
  explicit Deadlock(const std::string& dump) : std::runtime_error(dump) {}
};

// Thrown by Runtime::run() and par() when more than one process failed;
// what() holds the first failure followed by a summary of the others.
struct ProcessesFailed : std::runtime_error {
  explicit ProcessesFailed(const std::string& summary) : std::runtime_error(summary) {}
};

}  // namespace csp
