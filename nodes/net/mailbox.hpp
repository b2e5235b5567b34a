// A mailbox: a fiber that only moves packets from a local network port into
// a bounded buffer channel, so the process behind it may block on its own
// injection without ever stopping its port from draining (the network's
// consumption assumption, router.hpp).
//
// Who wakes whom: the network's delivery link wakes the mailbox; the
// mailbox's buffered write wakes the owner. The buffer capacity must be at
// least the number of packets that can be outstanding for the owner at once
// (the machine protocol bounds it); then the mailbox never blocks on the
// buffer and the port always drains. The mailbox ends when the network is
// shut down (its port is poisoned).
#pragma once

#include <cstddef>
#include <string>

#include "csp/csp.hpp"
#include "nodes/net/packet.hpp"

namespace nodes {

class Mailbox {
 public:
  Mailbox(std::string name, std::size_t capacity) : buffer_(std::move(name), capacity) {}

  // The mailbox process body: forward every packet from port to the buffer.
  void forward(csp::In<Packet> port) const;
  csp::In<Packet> reader() const { return buffer_.reader(); }

 private:
  csp::Channel<Packet> buffer_;
};

}  // namespace nodes
