// Comparing ranks' clocks for a recording over several ranks; see rank_clock.hpp.
#include "nodes/machine/rank_clock.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace nodes {

namespace {

constexpr int rounds = 8;

// The next message on `tag` from `from`, polled for without sleeping: the
// other side answers at once, and a nap would be the error itself.
Incoming take_at_once(Transport& transport, Tag tag, int from) {
  for (;;) {
    transport.progress();
    if (auto m = transport.poll(tag)) {
      if (m->from != from)
        throw std::logic_error("clock: a ping or answer from rank " + std::to_string(m->from) + ", not " +
                               std::to_string(from));
      return std::move(*m);
    }
  }
}

Incoming next(Transport& transport, int round, int from) {
  // The first may wait for the other rank to finish its report: sleep then.
  return round == 0 ? transport.receive(Tag::clock, from) : take_at_once(transport, Tag::clock, from);
}

}  // namespace

ClockOffset clock_offset(Transport& transport, int rank, const RouteRecorder& clock) {
  ClockOffset best{0, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < rounds; ++k) {
    const double sent = clock.now();
    transport.post(rank, Tag::clock, Bytes{std::byte{0}});
    transport.flush();
    const Incoming answer = next(transport, k, rank);
    const double back = clock.now();
    WireReader r(answer.bytes);
    const auto theirs = r.get<double>();
    if (back - sent < best.round_trip) best = {(sent + back) / 2 - theirs, back - sent};
  }
  return best;
}

void answer_clock(Transport& transport, const RouteRecorder& clock) {
  for (int k = 0; k < rounds; ++k) {
    (void)next(transport, k, 0);
    WireWriter w;
    w.put(clock.now());
    transport.post(0, Tag::clock, w.take());
    transport.flush();
  }
}

std::uint64_t rank_budget(std::uint64_t total, int ranks, int rank) {
  const auto r = static_cast<std::uint64_t>(std::max(ranks, 1));
  return total / r + (static_cast<std::uint64_t>(rank) < total % r ? 1 : 0);
}

}  // namespace nodes
