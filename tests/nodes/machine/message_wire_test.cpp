// The payloads of the machine's messages (messages.hpp) on the wire: each
// comes back field for field, its bytes are exactly the fields of its list
// at their widths in their order, and a payload cut short is refused. The
// kinds with no payload (stop, worker_done, server_stop, server_done) have
// nothing to encode.
#include "nodes/machine/messages.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "wire_support.hpp"

namespace {

using nodes::Bytes;
using nodes::Tile;
using wire_test::bytes_of;
using wire_test::expect_prefixes_refused;
using wire_test::joined;
using wire_test::raw;

TEST(MessageWire, WorkRequestRoundTrips) {
  const nodes::WorkRequest request{0x1234, 0x0506};
  const Bytes bytes = bytes_of(nodes::encode_work_request(request));
  EXPECT_EQ(bytes.size(), 4u);
  EXPECT_EQ(bytes, raw(std::uint16_t{0x1234}, std::uint16_t{0x0506}));
  const nodes::WorkRequest back = nodes::decode_work_request(bytes);
  EXPECT_EQ(back.reply_port, 0x1234);
  EXPECT_EQ(back.tiles, 0x0506);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) { nodes::decode_work_request(b); });
}

TEST(MessageWire, WorkTileRoundTrips) {
  const Tile tile{0x01020304, 0x0a0b0c0d};
  const Bytes bytes = bytes_of(nodes::encode_tile(tile));
  EXPECT_EQ(bytes.size(), 8u);
  EXPECT_EQ(bytes, raw(std::uint32_t{0x01020304}, std::uint32_t{0x0a0b0c0d}));
  EXPECT_EQ(nodes::decode_tile(bytes), tile);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) { nodes::decode_tile(b); });
}

TEST(MessageWire, PageRequestRoundTrips) {
  const nodes::PageRequest request{0x00abcdef, 0x0777};
  const Bytes bytes = bytes_of(nodes::encode_page_request(request));
  EXPECT_EQ(bytes.size(), 6u);  // no padding between the page and the port
  EXPECT_EQ(bytes, raw(std::uint32_t{0x00abcdef}, std::uint16_t{0x0777}));
  const nodes::PageRequest back = nodes::decode_page_request(bytes);
  EXPECT_EQ(back.page, 0x00abcdefu);
  EXPECT_EQ(back.reply_port, 0x0777);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) { nodes::decode_page_request(b); });
}

TEST(MessageWire, ResultRoundTripsItsColoursBitExact) {
  const std::vector<tracer::Color> colors{{0.125f, -2.5f, 1e-30f}, {3.0f, 0.0f, 7.75f}, {1.0f, 2.0f, 4.0f}};
  const Tile tile{70000, 3};
  const Bytes bytes = bytes_of(nodes::encode_result(0x0203, tile, colors));
  EXPECT_EQ(bytes.size(), 2 + 8 + 3 * 12u);
  Bytes expected = raw(std::uint16_t{0x0203}, std::uint32_t{70000}, std::uint32_t{3});
  for (const tracer::Color& c : colors) expected = joined(expected, raw(c.r, c.g, c.b));
  EXPECT_EQ(bytes, expected);
  const nodes::ResultView back = nodes::decode_result(bytes);
  EXPECT_EQ(back.reply_port, 0x0203);
  EXPECT_EQ(back.tile, tile);
  ASSERT_EQ(back.rgb.size(), 3 * 12u);
  EXPECT_EQ(back.rgb.data(), bytes.data() + 10);  // a view into the payload
  for (std::uint32_t i = 0; i < 3; ++i) EXPECT_EQ(back.color(i), colors[i]);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) { nodes::decode_result(b); });
  Bytes longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_THROW(nodes::decode_result(longer), std::runtime_error);
  EXPECT_THROW(nodes::encode_result(1, {0, 2}, colors), std::logic_error);
}

TEST(MessageWire, EmptyResultIsItsHeaderOnly) {
  const Bytes bytes = bytes_of(nodes::encode_result(9, {5, 0}, {}));
  EXPECT_EQ(bytes, raw(std::uint16_t{9}, std::uint32_t{5}, std::uint32_t{0}));
  const nodes::ResultView back = nodes::decode_result(bytes);
  EXPECT_EQ(back.tile, (Tile{5, 0}));
  EXPECT_TRUE(back.rgb.empty());
}

// The page's bytes run to the end with no count: the payload's size is
// the page's, so only a cut inside the id can be seen.
TEST(MessageWire, PageReplyRoundTrips) {
  std::vector<std::byte> page(64);
  for (std::size_t i = 0; i < page.size(); ++i) page[i] = static_cast<std::byte>(i * 3 + 1);
  const Bytes bytes = bytes_of(nodes::encode_page_reply(0x01000002, page));
  EXPECT_EQ(bytes.size(), 4 + page.size());
  EXPECT_EQ(bytes, joined(raw(std::uint32_t{0x01000002}), page));
  EXPECT_EQ(nodes::page_reply_id(bytes), 0x01000002u);
  const auto back = nodes::page_reply_bytes(bytes);
  EXPECT_EQ(back.data(), bytes.data() + 4);
  EXPECT_EQ(std::vector<std::byte>(back.begin(), back.end()), page);
  const std::span<const std::byte> id = std::span(bytes).first(4);
  expect_prefixes_refused(id, [](std::span<const std::byte> b) { nodes::page_reply_id(b); });
  expect_prefixes_refused(id, [](std::span<const std::byte> b) { nodes::page_reply_bytes(b); });
  EXPECT_TRUE(nodes::page_reply_bytes(id).empty());
}

// The shared form carries the id alone as payload, the bytes of the copy.
TEST(MessageWire, SharedPageReplyCarriesTheIdAsPayload) {
  const std::vector<std::byte> page{std::byte{5}, std::byte{6}, std::byte{7}};
  const nodes::Packet reply = nodes::make_page_reply(3, 4, 0x0badcafe, page);
  EXPECT_EQ(bytes_of(reply.payload), raw(std::uint32_t{0x0badcafe}));
  EXPECT_EQ(reply.payload, nodes::encode_page_reply(0x0badcafe, {}));
  EXPECT_EQ(nodes::page_reply_id(reply), 0x0badcafeu);
  EXPECT_EQ(nodes::page_reply_bytes(reply).data(), page.data());
}

}  // namespace
