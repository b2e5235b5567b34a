// The route recorder's clock and budget (see route_log.hpp).
#include "nodes/net/route_log.hpp"

#include "csp/virtual_time.hpp"

namespace nodes {

RouteRecorder::RouteRecorder(std::uint64_t max_packets, bool virtual_time,
                             std::chrono::steady_clock::time_point started)
    : max_packets_(max_packets), virtual_time_(virtual_time), started_(started), left_(max_packets) {}

double RouteRecorder::now() const {
  if (virtual_time_) return std::chrono::duration<double>(csp::this_process::now()).count();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

bool RouteRecorder::admit() {
  // Once the budget is spent every router only reads the word: it stays in
  // each core's cache and costs no more than a local variable.
  std::uint64_t left = left_.load(std::memory_order_relaxed);
  while (left > 0)
    if (left_.compare_exchange_weak(left, left - 1, std::memory_order_relaxed)) return true;
  return false;
}

}  // namespace nodes
