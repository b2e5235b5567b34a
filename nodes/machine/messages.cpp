// Payload encodings of the machine's messages (see messages.hpp).
#include "nodes/machine/messages.hpp"

#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace nodes {

namespace {

// Written straight into the packet's payload: one that fits in a packet
// takes no allocation.
template <class T>
Payload encode(const T& message, std::size_t bytes) {
  Payload payload;
  payload.reserve(bytes);
  BasicWireWriter<Payload&> w(payload);
  put_fields(w, message);
  return payload;
}

template <class T>
T decode(std::span<const std::byte> payload, const char* what) {
  WireReader r(payload);
  try {
    return get_fields<T>(r);
  } catch (const std::runtime_error&) {
    throw std::runtime_error(std::string("malformed ") + what + " message: payload too short");
  }
}

constexpr std::size_t work_request_bytes = 2 * sizeof(std::uint16_t);
constexpr std::size_t tile_bytes = 2 * sizeof(std::uint32_t);
constexpr std::size_t result_header_bytes = sizeof(std::uint16_t) + tile_bytes;
constexpr std::size_t page_request_bytes = sizeof(std::uint32_t) + sizeof(std::uint16_t);
constexpr std::size_t page_id_bytes = sizeof(std::uint32_t);
constexpr std::size_t color_bytes = 3 * sizeof(float);
static_assert(sizeof(tracer::Color) == color_bytes && std::is_trivially_copyable_v<tracer::Color>,
              "a result's colours are copied as raw r, g, b floats");

}  // namespace

std::string_view message_kind_name(std::uint8_t kind) {
  static constexpr std::array<std::string_view, message_kind_count> names{
      "unknown",     "work_request", "work",        "stop",        "result",    "page_request",
      "page_reply",  "worker_done",  "server_stop", "server_done"};
  return kind < names.size() ? names[kind] : names[0];
}

tracer::Color ResultView::color(std::uint32_t i) const {
  tracer::Color c;
  std::memcpy(&c.r, rgb.data() + i * color_bytes, sizeof(float));
  std::memcpy(&c.g, rgb.data() + i * color_bytes + sizeof(float), sizeof(float));
  std::memcpy(&c.b, rgb.data() + i * color_bytes + 2 * sizeof(float), sizeof(float));
  return c;
}

Packet make_packet(NodeId destination, std::uint16_t port, MessageKind kind, Payload payload) {
  Packet p;
  p.destination = destination;
  p.port = port;
  p.kind = static_cast<std::uint8_t>(kind);
  p.payload = std::move(payload);
  return p;
}

Payload encode_work_request(WorkRequest request) {
  return encode(request, work_request_bytes);
}

WorkRequest decode_work_request(std::span<const std::byte> payload) {
  return decode<WorkRequest>(payload, "work_request");
}

Payload encode_tile(Tile tile) { return encode(tile, tile_bytes); }

Tile decode_tile(std::span<const std::byte> payload) { return decode<Tile>(payload, "work"); }

Payload encode_result(std::uint16_t reply_port, Tile tile, std::span<const tracer::Color> colors) {
  if (colors.size() != tile.count) throw std::logic_error("result: colour count differs from tile size");
  // A Color is exactly its three floats (see color_bytes), so the run goes as one block.
  const ResultView result{reply_port, tile, std::as_bytes(colors)};
  return encode(result, result_header_bytes + result.rgb.size());
}

ResultView decode_result(std::span<const std::byte> payload) {
  const auto result = decode<ResultView>(payload, "result");
  if (result.rgb.size() != std::size_t{result.tile.count} * color_bytes)
    throw std::runtime_error("malformed result message: size does not match its pixel count");
  return result;
}

Payload encode_page_request(PageRequest request) {
  return encode(request, page_request_bytes);
}

PageRequest decode_page_request(std::span<const std::byte> payload) {
  return decode<PageRequest>(payload, "page_request");
}

Payload encode_page_reply(std::uint32_t page, std::span<const std::byte> bytes) {
  return encode(PageReplyView{page, bytes}, page_id_bytes + bytes.size());
}

std::uint32_t page_reply_id(std::span<const std::byte> payload) {
  return decode<PageReplyView>(payload, "page_reply").page;
}

std::span<const std::byte> page_reply_bytes(std::span<const std::byte> payload) {
  return decode<PageReplyView>(payload, "page_reply").bytes;
}

Packet make_page_reply(NodeId destination, std::uint16_t port, std::uint32_t page,
                       std::span<const std::byte> bytes) {
  Packet p = make_packet(destination, port, MessageKind::page_reply, encode_page_reply(page, {}));
  p.shared = bytes;
  return p;
}

std::uint32_t page_reply_id(const Packet& reply) { return page_reply_id(reply.payload); }

std::span<const std::byte> page_reply_bytes(const Packet& reply) {
  if (reply.shared.empty()) return page_reply_bytes(reply.payload);
  if (reply.payload.size() != page_id_bytes)
    throw std::runtime_error("malformed page_reply message: a shared page after more than its id");
  return reply.shared;
}

}  // namespace nodes
