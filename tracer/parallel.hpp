// Work shared among OS threads in fixed pieces. The pieces, and so what each
// computes, depend only on the input; threads only decide who computes which
// piece. A caller that merges piece results in piece order therefore gets the
// same result for any number of threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <type_traits>
#include <vector>

namespace tracer {

// Runs work(i) for every i in [0, pieces), on this thread and on up to
// threads - 1 others (0 and 1: this thread only), each taking the next piece
// from a shared counter, in order. Work that also takes an unsigned is told
// which thread runs it: 0 for this one, 1.. for the others, so per-thread
// state can be kept in a vector of `threads`. Returns once every thread it
// started has stopped; the first exception thrown stops the others before
// their next piece and is rethrown here. If no thread can be started, this
// thread does the rest.
template <class Work>
void parallel_pieces(unsigned threads, std::size_t pieces, const Work& work) {
  std::atomic<std::size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto drain = [&](unsigned worker) {
    try {
      for (std::size_t i; (i = next.fetch_add(1)) < pieces;) {
        if constexpr (std::is_invocable_v<const Work&, std::size_t, unsigned>)
          work(i, worker);
        else
          work(i);
      }
    } catch (...) {
      std::lock_guard lock(error_mutex);
      if (!error) error = std::current_exception();
      next.store(pieces);
    }
  };
  std::vector<std::thread> helpers;
  const std::size_t wanted = std::min<std::size_t>(threads > 1 ? threads - 1 : 0, pieces > 0 ? pieces - 1 : 0);
  try {
    for (std::size_t h = 0; h < wanted; ++h) helpers.emplace_back(drain, static_cast<unsigned>(h + 1));
  } catch (const std::system_error&) {  // fewer helpers, then
  }
  drain(0);
  for (std::thread& t : helpers) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace tracer
