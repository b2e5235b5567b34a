// Exceptions of the CSP runtime, and message_of for a stored one.
// Poisoned ends a process normally (it is how a network shuts down); Deadlock,
// ProcessesFailed, ProcessNotStarted and ThreadNotStarted are what
// Runtime::run() reports when a run goes wrong.
#pragma once

#include <exception>
#include <stdexcept>
#include <string>

namespace csp {

// The message of a stored exception: what() of a std::exception, else
// "unknown exception". For reporting a process's failure in one line.
inline std::string message_of(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown exception";
  }
}

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
// out_of_memory() is true when any of them failed with std::bad_alloc, or
// when no memory was left to record why they failed, so a caller can say
// what to do about it.
struct ProcessesFailed : std::runtime_error {
  ProcessesFailed(const std::string& summary, bool out_of_memory)
      : std::runtime_error(summary), out_of_memory_(out_of_memory) {}
  bool out_of_memory() const noexcept { return out_of_memory_; }

 private:
  bool out_of_memory_;
};

// Thrown by Runtime::run() when a spawned process could not start (no
// memory for its stack or its scheduling record), and by par() for a child
// that could not: what() names the first and counts the others. The
// processes that waited for it were unwound, as in a deadlock, which this
// error reports in its place, being the cause.
struct ProcessNotStarted : std::runtime_error {
  explicit ProcessNotStarted(const std::string& what) : std::runtime_error(what) {}
};

// Thrown by Runtime::run() when one of its OS threads could not be started
// or set up (no memory for its stack, or a limit on threads): no process ran.
struct ThreadNotStarted : std::runtime_error {
  explicit ThreadNotStarted(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace csp
