// What bridges send one another (bridge_wire.hpp): a cut link, a packet,
// a credit and an abort come back field for field, their bytes are exactly
// the fields of their lists at their widths, a page reply's shared bytes
// arrive as payload, and a frame cut short is refused. (It builds the
// machine's messages, so it sits in the machine's suite rather than in
// tests/nodes/ranks, which runs the bridge itself.)
#include "nodes/ranks/bridge_wire.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "nodes/machine/messages.hpp"
#include "wire_support.hpp"

namespace {

using nodes::Bytes;
using nodes::Packet;
using nodes::WireReader;
using nodes::WireWriter;
using wire_test::expect_prefixes_refused;
using wire_test::joined;
using wire_test::raw;

Bytes put_link(const nodes::CutLink& link) {
  WireWriter w;
  nodes::put_link(w, link);
  return w.take();
}

Bytes put_packet(const Packet& p) {
  WireWriter w;
  nodes::put_packet(w, p);
  return w.take();
}

// A traced page reply whose page is shared, every field its own value.
Packet traced_reply(const std::vector<std::byte>& page) {
  Packet p = nodes::make_page_reply(0x00070009, 0x0304, 0x00abcdef, page);
  p.source = 0x00020005;
  p.hops = 0x0102;
  p.traced = true;
  p.recorded = true;
  p.id = 0x1122334455667788;
  p.route = {0x00020005, 0x00030006, 0x00070009};
  return p;
}

TEST(BridgeWire, LinkRoundTrips) {
  const nodes::CutLink link{0x00012345, 0x00067890, 3};
  const Bytes bytes = put_link(link);
  EXPECT_EQ(bytes.size(), 9u);  // the buffer class goes as one byte
  EXPECT_EQ(bytes, raw(std::uint32_t{0x00012345}, std::uint32_t{0x00067890}, std::uint8_t{3}));
  WireReader r(bytes);
  const nodes::CutLink back = nodes::get_link(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.from, link.from);
  EXPECT_EQ(back.to, link.to);
  EXPECT_EQ(back.buffer_class, link.buffer_class);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) {
    WireReader cut(b);
    nodes::get_link(cut);
  });
}

TEST(BridgeWire, TracedSharedPageReplyRoundTrips) {
  std::vector<std::byte> page(40);
  for (std::size_t i = 0; i < page.size(); ++i) page[i] = static_cast<std::byte>(200 - i);
  const Packet p = traced_reply(page);
  const Bytes bytes = put_packet(p);
  const nodes::Payload encoded = nodes::encode_page_reply(0x00abcdef, page);  // the id, then the page
  const Bytes payload = wire_test::bytes_of(encoded);
  const Bytes head = raw(p.source, p.destination, p.kind, p.port, p.hops, std::uint8_t{1}, std::uint8_t{1}, p.id);
  EXPECT_EQ(head.size(), 4 + 4 + 1 + 2 + 2 + 1 + 1 + 8u);
  EXPECT_EQ(bytes.size(), head.size() + 8 + payload.size() + 8 + 3 * 4);
  const Bytes route = raw(std::uint64_t{3}, p.route[0], p.route[1], p.route[2]);
  EXPECT_EQ(bytes, joined(joined(joined(head, raw(std::uint64_t{payload.size()})), payload), route));

  WireReader r(bytes);
  const Packet back = nodes::get_packet(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.source, p.source);
  EXPECT_EQ(back.destination, p.destination);
  EXPECT_EQ(back.kind, p.kind);
  EXPECT_EQ(back.port, p.port);
  EXPECT_EQ(back.hops, p.hops);
  EXPECT_TRUE(back.traced);
  EXPECT_TRUE(back.recorded);  // travels: the other rank's routers log its hops
  EXPECT_EQ(back.id, p.id);
  EXPECT_EQ(back.payload, encoded);
  EXPECT_TRUE(back.shared.empty());
  EXPECT_EQ(back.bytes(), p.bytes());
  EXPECT_EQ(back.route, p.route);
  const auto got = nodes::page_reply_bytes(back);
  EXPECT_EQ(std::vector<std::byte>(got.begin(), got.end()), page);
}

TEST(BridgeWire, UntracedPacketRoundTrips) {
  Packet p = nodes::make_packet(6, 2, nodes::MessageKind::result, {std::byte{9}, std::byte{8}});
  p.source = 1;
  p.id = 77;
  const Bytes bytes = put_packet(p);
  EXPECT_EQ(bytes.size(), 23 + 8 + 2 + 8u);
  EXPECT_EQ(bytes[13], std::byte{0});  // traced, as one byte
  EXPECT_EQ(bytes[14], std::byte{0});  // recorded, as one byte
  WireReader r(bytes);
  const Packet back = nodes::get_packet(r);
  EXPECT_FALSE(back.traced);
  EXPECT_FALSE(back.recorded);
  EXPECT_EQ(back.payload, p.payload);
  EXPECT_TRUE(back.route.empty());
  // Any byte but 0 reads as traced.
  Bytes other = bytes;
  other[13] = std::byte{2};
  WireReader o(other);
  EXPECT_TRUE(nodes::get_packet(o).traced);
}

TEST(BridgeWire, CreditRoundTrips) {
  const nodes::CreditRecord credit{{0x00010203, 0x00040506, 2}, 0x00070809};
  WireWriter w;
  nodes::put_fields(w, credit);
  const Bytes bytes = w.take();
  EXPECT_EQ(bytes, raw(std::uint32_t{0x00010203}, std::uint32_t{0x00040506}, std::uint8_t{2},
                       std::uint32_t{0x00070809}));
  WireReader r(bytes);
  const auto back = nodes::get_fields<nodes::CreditRecord>(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.link.from, credit.link.from);
  EXPECT_EQ(back.link.to, credit.link.to);
  EXPECT_EQ(back.link.buffer_class, credit.link.buffer_class);
  EXPECT_EQ(back.count, credit.count);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) {
    WireReader cut(b);
    nodes::get_fields<nodes::CreditRecord>(cut);
  });
}

TEST(BridgeWire, AbortRoundTrips) {
  const nodes::AbortRecord abort{-3, "process 'worker' failed: out of pages"};
  WireWriter w;
  nodes::put_fields(w, abort);
  const Bytes bytes = w.take();
  EXPECT_EQ(bytes.size(), 4 + 8 + abort.text.size());
  const std::span<const char> text(abort.text);
  EXPECT_EQ(bytes, joined(raw(std::int32_t{-3}, std::uint64_t{abort.text.size()}), std::as_bytes(text)));
  WireReader r(bytes);
  const auto back = nodes::get_fields<nodes::AbortRecord>(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.rank, -3);
  EXPECT_EQ(back.text, abort.text);
  expect_prefixes_refused(bytes, [](std::span<const std::byte> b) {
    WireReader cut(b);
    nodes::get_fields<nodes::AbortRecord>(cut);
  });
}

// As the bridge frames them: records one after another, read back in order
// with nothing left over; every cut of the frame is refused.
TEST(BridgeWire, AFrameOfLinksAndPacketsReadsBackInOrder) {
  const std::vector<std::byte> page(16, std::byte{0x5a});
  WireWriter w;
  nodes::put_link(w, {1, 2, 0});
  nodes::put_packet(w, traced_reply(page));
  nodes::put_link(w, {3, 4, 1});
  nodes::put_packet(w, nodes::make_packet(4, 0, nodes::MessageKind::stop));
  const Bytes frame = w.take();
  const auto read_all = [](std::span<const std::byte> b) {
    WireReader r(b);
    std::vector<Packet> packets;
    for (int i = 0; i < 2; ++i) {
      nodes::get_link(r);
      packets.push_back(nodes::get_packet(r));
    }
    return std::make_pair(packets, r.done());
  };
  const auto [packets, done] = read_all(frame);
  EXPECT_TRUE(done);
  EXPECT_EQ(packets[0].id, 0x1122334455667788u);
  EXPECT_EQ(packets[1].kind, static_cast<std::uint8_t>(nodes::MessageKind::stop));
  EXPECT_TRUE(packets[1].payload.empty());
  expect_prefixes_refused(frame, read_all);
}

TEST(BridgeWire, ARouteLongerThanTheMessageIsRefused) {
  const std::vector<std::byte> no_page;
  Bytes bytes = put_packet(traced_reply(no_page));
  // The route's count is the 8 bytes before its 3 nodes, at the end.
  const Bytes huge = raw(std::numeric_limits<std::uint64_t>::max() / 4);
  wire_test::overwrite(bytes, bytes.size() - 12 - 8, huge);
  WireReader r(bytes);
  EXPECT_THROW(nodes::get_packet(r), std::runtime_error);
}

}  // namespace
