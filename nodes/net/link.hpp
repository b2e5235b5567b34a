// A link process: the wire of one buffer class of one link (or the delivery
// stage into a local port) when the network models link costs. It takes the
// next packet from the output queue its router writes (a bounded buffer
// channel), holds it for latency + bytes / bandwidth — a real sleep, or
// virtual time under csp's virtual-time scheduler (csp::this_process::delay)
// — and hands it on to the neighbour router's input channel (or the local
// port). One packet at a time: the link is busy while it carries one.
//
// Who wakes whom: the router's write wakes the link; the link's write wakes
// the neighbour's router (its ALT) and may block: only this process waits,
// never the router. Without a link model there is no link process: the
// router's output queue is the neighbour's input channel itself.
// Ends: the process stops when any of its channels is poisoned.
#pragma once

#include <chrono>
#include <cstdint>

#include "csp/csp.hpp"
#include "nodes/net/packet.hpp"

namespace nodes {

// Optional cost of crossing one link: e.g. iPSC/2 Direct-Connect links carry
// about 2.8 MB/s. Zero bandwidth means infinitely fast.
struct LinkModel {
  std::chrono::nanoseconds latency{0};
  double bytes_per_second = 0.0;

  bool enabled() const { return latency.count() > 0 || bytes_per_second > 0.0; }
  std::chrono::nanoseconds delay(std::size_t bytes) const;
};

// Traffic of one output queue, counted by the router that writes it.
struct LinkCounters {
  std::uint64_t packets = 0;
  std::uint64_t bytes = 0;  // payload bytes
};

class Link {
 public:
  Link(csp::In<Packet> queue, csp::Out<Packet> next, LinkModel model);
  void run();

 private:
  csp::In<Packet> queue_;
  csp::Out<Packet> next_;
  LinkModel model_;
};

}  // namespace nodes
