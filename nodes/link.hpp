// A link process: the output stage of one buffer class of one link (or of a
// local delivery port). It owns no queue of its own beyond the packet it
// carries; the bounded queue lives in the router it pulls from.
//
// Protocol (who wakes whom):
//   link   -> router   request.write(Ready{})   "I can take a packet"
//   router -> link     reply.write(packet)      only in answer to a request,
//                                               so it never blocks for long
//   link   -> next     next.write(packet)       the neighbour router's input
//                                               channel (or the local port);
//                                               may block: only this process
//                                               waits, never the router.
// With a link model the packet is delayed (latency + bytes / bandwidth)
// between reply and next, modelling the wire: a real sleep, or virtual time
// under csp's virtual-time scheduler (csp::this_process::delay).
// Ends: the process stops when any of its channels is poisoned.
#pragma once

#include <chrono>
#include <cstdint>

#include "csp/csp.hpp"
#include "nodes/packet.hpp"

namespace nodes {

struct Ready {};

// Optional cost of crossing one link: e.g. iPSC/2 Direct-Connect links carry
// about 2.8 MB/s. Zero bandwidth means infinitely fast.
struct LinkModel {
  std::chrono::nanoseconds latency{0};
  double bytes_per_second = 0.0;

  bool enabled() const { return latency.count() > 0 || bytes_per_second > 0.0; }
  std::chrono::nanoseconds delay(std::size_t bytes) const;
};

// Owned by one link process; read only after the runtime has stopped.
struct LinkCounters {
  std::uint64_t packets = 0;
  std::uint64_t bytes = 0;  // payload bytes
};

class Link {
 public:
  Link(csp::Out<Ready> request, csp::In<Packet> reply, csp::Out<Packet> next, LinkModel model,
       LinkCounters& counters);
  void run();

 private:
  csp::Out<Ready> request_;
  csp::In<Packet> reply_;
  csp::Out<Packet> next_;
  LinkModel model_;
  LinkCounters& counters_;
};

}  // namespace nodes
