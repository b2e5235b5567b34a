// A cut link and a packet to and from bytes by their field lists; see bridge_wire.hpp.
#include "nodes/ranks/bridge_wire.hpp"

namespace nodes {

void put_link(WireWriter& w, const CutLink& link) { put_fields(w, link); }

CutLink get_link(WireReader& r) { return get_fields<CutLink>(r); }

void put_packet(WireWriter& w, const Packet& packet) { put_fields(w, packet); }

Packet get_packet(WireReader& r) { return get_fields<Packet>(r); }

}  // namespace nodes
