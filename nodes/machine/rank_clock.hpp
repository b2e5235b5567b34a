// nodes::clock_offset and answer_clock: how rank 0 puts another rank's run
// clock onto its own, for a recording made over several ranks. Rank 0 pings
// the rank a few times; each answer is that rank's clock at once, which
// falls between the ping's sending and the answer's arrival on rank 0's
// clock, so the round trip of least delay bounds the error by half of it.
// Both sides poll without sleeping after the first ping, so on one host
// the error is a few microseconds; across hosts, what the network adds.
// The two sides make the same number of rounds, on Tag::clock only.
#pragma once

#include <cstdint>

#include "nodes/machine/recorder.hpp"
#include "nodes/ranks/transport.hpp"

namespace nodes {

// Rank 0's view of rank `rank`'s clock: the seconds to add to a time on it
// to put it on `clock`'s (rank 0's), and the quickest round trip, half of
// which bounds the offset's error.
struct ClockOffset {
  double offset = 0;
  double round_trip = 0;
};
ClockOffset clock_offset(Transport& transport, int rank, const RouteRecorder& clock);

// Any other rank: answers each of rank 0's pings with `clock`'s reading.
void answer_clock(Transport& transport, const RouteRecorder& clock);

// The packets rank `rank` of `ranks` records of a run's `total`: the
// budget shared out, the first ranks taking one more where it does not
// divide.
std::uint64_t rank_budget(std::uint64_t total, int ranks, int rank);

}  // namespace nodes
