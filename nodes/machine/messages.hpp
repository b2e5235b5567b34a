// The application's messages on the machine network: packet kinds, the local
// ports of a processor, and the byte encoding of each payload.
//
// Every message travels as a nodes::Packet by value (processors share
// nothing); the payload is a flat little-endian-as-host byte string written
// and read here only, so a processor could run unchanged in another process.
// Each payload's layout is the one field list below, in wire order, that
// its encoder and decoder both go by (wire_fields.hpp): fixed-width fields
// with no padding and no counts; a result's colours and a page reply's
// bytes run to the end of the payload. Decoding checks sizes and throws
// std::runtime_error on a malformed payload rather than reading out of
// bounds. Who sends what, and when: docs/architecture.md, "Messages".
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/net/router.hpp"
#include "nodes/ranks/wire_fields.hpp"
#include "tracer/vec.hpp"

namespace nodes {

enum class MessageKind : std::uint8_t {
  work_request = 1,
  work,
  stop,
  result,
  page_request,
  page_reply,
  worker_done,
  server_stop,
  server_done,
};
inline constexpr int message_kind_count = 10;  // one past the last kind

// Name for reports and route traces ("page_reply" etc.).
std::string_view message_kind_name(std::uint8_t kind);

// Local ports of a processor. The farmer exists on node 0 only; worker w of
// a node listens on first_worker + w.
struct Ports {
  static constexpr std::uint16_t page_server = 0;
  static constexpr std::uint16_t farmer = 1;
  static constexpr std::uint16_t first_worker = 2;
  static constexpr std::uint16_t count(int workers_per_node) {
    return static_cast<std::uint16_t>(first_worker + workers_per_node);
  }
};

// A contiguous run of work items (pixels or SPD corner samples) in the
// machine's pixel order: items first .. first + count - 1.
struct Tile {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  bool operator==(const Tile&) const = default;
};

struct PageRequest {
  std::uint32_t page = 0;
  std::uint16_t reply_port = 0;
};

// A worker's first message: send `tiles` answers (work or stop) to reply_port.
struct WorkRequest {
  std::uint16_t reply_port = 0;
  std::uint16_t tiles = 0;
};

struct ResultView {
  std::uint16_t reply_port = 0;  // where the answer to the request it carries goes
  Tile tile;
  std::span<const std::byte> rgb;  // tile.count x 3 floats, bit-exact
  tracer::Color color(std::uint32_t i) const;
};

// A page reply: the page id leads the bytes so a reply names what it carries.
struct PageReplyView {
  std::uint32_t page = 0;
  std::span<const std::byte> bytes;
};

// The payloads, in wire order: 4, 8, 6 + 12 x count, 6 and 4 + page bytes.
template <class V>
void wire_fields(V& v, WireView<WorkRequest> auto& request) {
  v(request.reply_port);
  v(request.tiles);
}

template <class V>
void wire_fields(V& v, WireView<Tile> auto& tile) {
  v(tile.first);
  v(tile.count);
}

template <class V>
void wire_fields(V& v, WireView<ResultView> auto& result) {
  v(result.reply_port);
  v(result.tile);
  v(wire_rest(result.rgb));
}

template <class V>
void wire_fields(V& v, WireView<PageRequest> auto& request) {
  v(request.page);
  v(request.reply_port);
}

template <class V>
void wire_fields(V& v, WireView<PageReplyView> auto& reply) {
  v(reply.page);
  v(wire_rest(reply.bytes));
}

Payload encode_work_request(WorkRequest request);
WorkRequest decode_work_request(std::span<const std::byte> payload);

Payload encode_tile(Tile tile);
Tile decode_tile(std::span<const std::byte> payload);

Payload encode_result(std::uint16_t reply_port, Tile tile, std::span<const tracer::Color> colors);
ResultView decode_result(std::span<const std::byte> payload);

Payload encode_page_request(PageRequest request);
PageRequest decode_page_request(std::span<const std::byte> payload);

// A packet to (destination, port); the network stamps the source.
Packet make_packet(NodeId destination, std::uint16_t port, MessageKind kind, Payload payload = {});

// A process's injection end that numbers its packets: ids interleave over
// all sending processes (first id = the process's index, step = their
// count), so ids below K cover the first packets of every process, which is
// what route tracing (NetworkOptions::trace_routes) selects.
class Outbox {
 public:
  Outbox(Injector out, std::uint64_t index, std::uint64_t processes)
      : out_(std::move(out)), next_id_(index), step_(processes) {}
  void send(Packet packet) {
    packet.id = next_id_;
    next_id_ += step_;
    out_.write(std::move(packet));
  }
  bool room_hint() const { return out_.room_hint(); }  // Injector::room_hint

 private:
  Injector out_;
  std::uint64_t next_id_;
  std::uint64_t step_;
};

Payload encode_page_reply(std::uint32_t page, std::span<const std::byte> bytes);
std::uint32_t page_reply_id(std::span<const std::byte> payload);
std::span<const std::byte> page_reply_bytes(std::span<const std::byte> payload);

// The same reply with the page's bytes carried by reference (Packet::shared):
// an owner's page never changes while the machine runs, so inside one
// process it is copied once, into the cache slot of the node that asked.
// Its bytes on the wire and in every count are those of encode_page_reply.
Packet make_page_reply(NodeId destination, std::uint16_t port, std::uint32_t page,
                       std::span<const std::byte> bytes);
// A reply of either form.
std::uint32_t page_reply_id(const Packet& reply);
std::span<const std::byte> page_reply_bytes(const Packet& reply);

}  // namespace nodes
