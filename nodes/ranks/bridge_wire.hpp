// The byte form of what bridges (bridge.hpp) send one another: a frame is
// records one after another, each a one-byte BridgeRecord, then its fields:
//   packet: the cut link it travels on, then the packet;
//   credit: a CreditRecord;   end: nothing;   abort: an AbortRecord.
// Each field list below is the whole format, read and written alike
// (wire_fields.hpp); the other rank decodes what was encoded, but a
// packet's shared bytes arrive as payload (joined after it, since the other
// process has no pointer to them). `recorded` travels, so that the routers
// of a recorded run log a packet's hops on every rank.
#pragma once

#include <cstdint>
#include <string>

#include "nodes/net/network.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/ranks/transport.hpp"
#include "nodes/ranks/wire_fields.hpp"

namespace nodes {

enum class BridgeRecord : std::uint8_t { packet = 1, credit, end, abort };

// Room for `count` more packets on `link`, returned to its sending rank.
struct CreditRecord {
  CutLink link;
  std::uint32_t count = 0;
};

// A failure on rank `rank`, as its one line.
struct AbortRecord {
  std::int32_t rank = 0;
  std::string text;
};

// 4 + 4 + 1 bytes: the ends as uint32, the buffer class as uint8.
template <class V>
void wire_fields(V& v, WireView<CutLink> auto& link) {
  v(wire_as<std::uint32_t>(link.from));
  v(wire_as<std::uint32_t>(link.to));
  v(wire_as<std::uint8_t>(link.buffer_class));
}

template <class V>
void wire_fields(V& v, WireView<Packet> auto& p) {
  v(p.source);
  v(p.destination);
  v(p.kind);
  v(p.port);
  v(p.hops);
  v(p.traced);
  v(p.recorded);
  v(p.id);
  v(wire_joined(p.payload, p.shared));
  v(p.route);
}

template <class V>
void wire_fields(V& v, WireView<CreditRecord> auto& credit) {
  v(credit.link);
  v(credit.count);
}

template <class V>
void wire_fields(V& v, WireView<AbortRecord> auto& abort) {
  v(abort.rank);
  v(abort.text);
}

void put_link(WireWriter& w, const CutLink& link);
CutLink get_link(WireReader& r);

void put_packet(WireWriter& w, const Packet& packet);
Packet get_packet(WireReader& r);

}  // namespace nodes
