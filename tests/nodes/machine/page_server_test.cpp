// The page server driven through its own channels by a test process: a
// page_request is answered to the asker's port with the page's bytes and
// counted, server_stop is answered with server_done to the farmer and ends
// it, and a page it does not own is a protocol error.
#include "nodes/machine/page_server.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "csp/csp.hpp"
#include "tests/nodes/machine/test_database.hpp"

namespace {

using nodes::MessageKind;
using nodes::Packet;
using nodes::Ports;

constexpr std::size_t page_size = 256;

std::vector<std::byte> page_bytes(std::uint32_t page) { return test::page_bytes(page, page_size); }

// Node 0 of 2, pages dealt modulo: it owns pages 0 and 2 of 4.
struct ScriptedServer {
  nodes::PagePlacement placement{nodes::Distribution::modulo, 2, 4};
  nodes::NodeMemory memory{placement, 0, page_size, {page_bytes(0), page_bytes(2)}, 1};
  csp::Channel<Packet> requests{"page requests", 4}, out{"server out", 4};
  nodes::ServerCounters counters;

  nodes::PageServer server() {
    return nodes::PageServer(0, memory, requests.reader(), nodes::Outbox(out.writer(), 0, 1), counters);
  }
};

Packet request(nodes::NodeId from, std::uint32_t page, std::uint16_t reply_port) {
  Packet p = nodes::make_packet(0, Ports::page_server, MessageKind::page_request,
                                nodes::encode_page_request({page, reply_port}));
  p.source = from;
  return p;
}

TEST(PageServer, AnswersARequestWithThePageThenStops) {
  ScriptedServer s;
  csp::Runtime runtime(1);
  runtime.spawn("page server", 0, [&s] { s.server().run(); });
  runtime.spawn("asker", 0, [&s] {
    s.requests.writer().write(request(1, 2, 3));
    const Packet reply = s.out.reader().read();
    EXPECT_EQ(static_cast<MessageKind>(reply.kind), MessageKind::page_reply);
    EXPECT_EQ(reply.destination, 1u);
    EXPECT_EQ(reply.port, 3u);
    EXPECT_EQ(nodes::page_reply_id(reply), 2u);
    const auto bytes = nodes::page_reply_bytes(reply);
    const auto expected = page_bytes(2);
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), expected.begin(), expected.end()));
    // The page travels by reference inside one process, but counts as the
    // bytes of a copy.
    EXPECT_EQ(reply.bytes(), nodes::encode_page_reply(2, expected).size());

    s.requests.writer().write(nodes::make_packet(0, Ports::page_server, MessageKind::server_stop));
    const Packet done = s.out.reader().read();
    EXPECT_EQ(static_cast<MessageKind>(done.kind), MessageKind::server_done);
    EXPECT_EQ(done.destination, 0u);
    EXPECT_EQ(done.port, Ports::farmer);
  });
  runtime.run();  // the server ended after server_done: nothing deadlocked
  EXPECT_EQ(s.counters.pages_served, 1u);
  EXPECT_EQ(s.counters.bytes_served, page_size);
}

TEST(PageServer, RefusesAPageItDoesNotOwn) {
  ScriptedServer s;
  csp::Runtime runtime(1);
  runtime.spawn("page server", 0, [&s] { s.server().run(); });
  runtime.spawn("asker", 0, [&s] { s.requests.writer().write(request(1, 1, 2)); });
  try {
    runtime.run();
    ADD_FAILURE() << "no error";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("page 1 it does not own"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.counters.pages_served, 0u);
}

}  // namespace
