// Payload encodings of the machine's messages (see messages.hpp).
#include "nodes/machine/messages.hpp"

#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace nodes {

namespace {

template <class T>
void put(std::vector<std::byte>& out, T value) {
  const auto at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

template <class T>
T get(std::span<const std::byte> in, std::size_t at, const char* what) {
  if (in.size() < at + sizeof(T))
    throw std::runtime_error(std::string("malformed ") + what + " message: payload too short");
  T value;
  std::memcpy(&value, in.data() + at, sizeof(T));
  return value;
}

constexpr std::size_t tile_bytes = 2 * sizeof(std::uint32_t);
constexpr std::size_t result_header_bytes = sizeof(std::uint16_t) + tile_bytes;
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

Packet make_packet(NodeId destination, std::uint16_t port, MessageKind kind, std::vector<std::byte> payload) {
  Packet p;
  p.destination = destination;
  p.port = port;
  p.kind = static_cast<std::uint8_t>(kind);
  p.payload = std::move(payload);
  return p;
}

std::vector<std::byte> encode_work_request(WorkRequest request) {
  std::vector<std::byte> out;
  put(out, request.reply_port);
  put(out, request.tiles);
  return out;
}

WorkRequest decode_work_request(std::span<const std::byte> payload) {
  return {get<std::uint16_t>(payload, 0, "work_request"), get<std::uint16_t>(payload, 2, "work_request")};
}

std::vector<std::byte> encode_tile(Tile tile) {
  std::vector<std::byte> out;
  out.reserve(tile_bytes);
  put(out, tile.first);
  put(out, tile.count);
  return out;
}

Tile decode_tile(std::span<const std::byte> payload) {
  return {get<std::uint32_t>(payload, 0, "work"), get<std::uint32_t>(payload, 4, "work")};
}

std::vector<std::byte> encode_result(std::uint16_t reply_port, Tile tile, std::span<const tracer::Color> colors) {
  if (colors.size() != tile.count) throw std::logic_error("result: colour count differs from tile size");
  std::vector<std::byte> out;
  out.reserve(result_header_bytes + colors.size() * color_bytes);
  put(out, reply_port);
  put(out, tile.first);
  put(out, tile.count);
  // A Color is exactly its three floats (see color_bytes), so the run copies as one block.
  out.resize(result_header_bytes + colors.size() * color_bytes);
  if (!colors.empty()) std::memcpy(out.data() + result_header_bytes, colors.data(), colors.size() * color_bytes);
  return out;
}

ResultView decode_result(std::span<const std::byte> payload) {
  const auto reply_port = get<std::uint16_t>(payload, 0, "result");
  const Tile tile{get<std::uint32_t>(payload, 2, "result"), get<std::uint32_t>(payload, 6, "result")};
  if (payload.size() != result_header_bytes + std::size_t{tile.count} * color_bytes)
    throw std::runtime_error("malformed result message: size does not match its pixel count");
  return {reply_port, tile, payload.subspan(result_header_bytes)};
}

std::vector<std::byte> encode_page_request(PageRequest request) {
  std::vector<std::byte> out;
  put(out, request.page);
  put(out, request.reply_port);
  return out;
}

PageRequest decode_page_request(std::span<const std::byte> payload) {
  return {get<std::uint32_t>(payload, 0, "page_request"), get<std::uint16_t>(payload, 4, "page_request")};
}

std::vector<std::byte> encode_page_reply(std::uint32_t page, std::span<const std::byte> bytes) {
  std::vector<std::byte> out;
  out.reserve(sizeof(page) + bytes.size());
  put(out, page);
  out.insert(out.end(), bytes.begin(), bytes.end());
  return out;
}

std::uint32_t page_reply_id(std::span<const std::byte> payload) {
  return get<std::uint32_t>(payload, 0, "page_reply");
}

std::span<const std::byte> page_reply_bytes(std::span<const std::byte> payload) {
  if (payload.size() < sizeof(std::uint32_t)) throw std::runtime_error("malformed page_reply message: no page id");
  return payload.subspan(sizeof(std::uint32_t));
}

Packet make_page_reply(NodeId destination, std::uint16_t port, std::uint32_t page,
                       std::span<const std::byte> bytes) {
  std::vector<std::byte> id;
  put(id, page);
  Packet p = make_packet(destination, port, MessageKind::page_reply, std::move(id));
  p.shared = bytes;
  return p;
}

std::uint32_t page_reply_id(const Packet& reply) { return page_reply_id(reply.payload); }

std::span<const std::byte> page_reply_bytes(const Packet& reply) {
  if (reply.shared.empty()) return page_reply_bytes(reply.payload);
  if (reply.payload.size() != sizeof(std::uint32_t))
    throw std::runtime_error("malformed page_reply message: a shared page after more than its id");
  return reply.shared;
}

}  // namespace nodes
