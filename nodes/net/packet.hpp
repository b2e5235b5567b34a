// nodes::Packet: the one message type of the machine network, moved by value
// through csp channels from router to router (processors share nothing).
//
// Invariants: hops counts links crossed so far (0 at injection); route is
// non-empty only for traced packets and then lists every node visited, the
// source first; a delivered traced packet has route.size() == hops + 1.
// kind is the application's own tag (the network only counts by it); port
// names the local process on the destination that receives the packet.
// shared: bytes the packet carries by reference, which nobody writes while
// the network runs (a page of the scene); inside one process the packet
// points at them rather than copying them, but in every count and delay
// they are bytes carried (bytes()), and across processes the bridge sends
// them as payload. A payload of up to inline_payload bytes (every message
// of the machine but a result) lies inside the packet: it takes no
// allocation, and crosses a thread in the packet's own cache lines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <boost/container/small_vector.hpp>

#include "topology/topology.hpp"

namespace nodes {

using topology::NodeId;

inline constexpr std::size_t inline_payload = 16;
class Payload : public boost::container::small_vector<std::byte, inline_payload> {
 public:
  using small_vector::small_vector;
  Payload() = default;
  Payload(const Payload&) = default;
  Payload(Payload&&) noexcept = default;
  Payload& operator=(const Payload&) = default;
  // Boost leaves a vector whose buffer was moved out with no storage at
  // all, not its inline one, so moving a short payload into it would
  // allocate, inside a noexcept operator: a packet in every slot a packet
  // was moved out of, and std::terminate where memory runs out. The
  // payload is made afresh instead, which never allocates.
  Payload& operator=(Payload&& other) noexcept;  // packet.cpp
  operator std::span<const std::byte>() const { return {data(), size()}; }
};

struct Packet {
  NodeId source = 0;       // set by the network at injection
  NodeId destination = 0;
  std::uint8_t kind = 0;   // application-defined tag
  std::uint16_t port = 0;  // local port on the destination
  std::uint16_t hops = 0;  // links crossed, counted by the routers
  bool traced = false;     // record the route (or the network decides: trace_routes)
  bool recorded = false;   // its hops go into the run's Recorder (set at injection)
  std::uint64_t id = 0;    // application-defined sequence number
  Payload payload;
  std::span<const std::byte> shared;  // follows the payload; read-only
  std::vector<NodeId> route;  // visited nodes, for traced packets only

  // The bytes carried: the payload, then the shared bytes.
  std::size_t bytes() const { return payload.size() + shared.size(); }
};

// Kinds used by the network's own tests and the traffic example; the
// machine's messages (messages.hpp) use small values, these stay clear.
inline constexpr std::uint8_t kind_traffic = 0xf0;
inline constexpr std::uint8_t kind_probe = 0xf1;

}  // namespace nodes
