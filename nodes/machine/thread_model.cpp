// The thread model's arithmetic (see thread_model.hpp).
#include "nodes/machine/thread_model.hpp"

#include <algorithm>
#include <cmath>

namespace nodes {

ThreadModel::Parts ThreadModel::parts(unsigned threads) const {
  // More threads than pixel computers leave the extra threads nothing to run.
  const double t_count = std::max(1.0, std::min(static_cast<double>(threads), std::max(1.0, pixel_computers)));
  const double r = std::log2(t_count);
  const double k = pixel_computers / t_count;
  const double between_misses = misses > 0 ? work_seconds / misses : 0;  // t
  Parts p;
  p.work = work_seconds / t_count;
  p.crossings = r * misses * crossing_seconds / t_count;
  p.idle = misses / t_count * std::max(0.0, r * latency_seconds - (k - 1) * between_misses);
  return p;
}

double ThreadModel::fit_crossing(double one_thread_seconds, double two_thread_seconds, double misses) {
  if (misses <= 0) return 0;
  return std::max(0.0, (2 * two_thread_seconds - one_thread_seconds) / misses);
}

double ThreadModel::fit_latency(double one_thread_seconds, double two_thread_seconds, double misses,
                                double crossing_seconds) {
  if (misses <= 0) return 0;
  return std::max(0.0, (2 * two_thread_seconds - one_thread_seconds - misses * crossing_seconds) / misses);
}

}  // namespace nodes
