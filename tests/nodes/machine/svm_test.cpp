// A node's shared virtual memory driven through its workers' channels: two
// pixel-computer fibers miss on one remote page while a test process plays
// the owner's page server. One page_request goes out, the second miss waits
// for the first (coalesced), both read the page's bytes, and an own page or
// a cached one sends nothing.
#include "nodes/machine/svm.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "tests/nodes/machine/test_database.hpp"

namespace {

using nodes::MessageKind;
using nodes::Packet;
using nodes::Ports;

constexpr std::size_t page_size = 256;

std::vector<std::byte> page_bytes(std::uint32_t page) { return test::page_bytes(page, page_size); }

bool holds_page(const std::byte* bytes, std::uint32_t page) {
  const auto expected = page_bytes(page);
  return std::equal(expected.begin(), expected.end(), bytes);
}

// Node 0 of 2 (pages dealt modulo: it owns 0 and 2 of 4), two workers on
// ports 2 and 3 of its own, both sending into one injection channel.
struct ScriptedSvm {
  nodes::PagePlacement placement{nodes::Distribution::modulo, 2, 4};
  nodes::NodeSvm svm{nodes::NodeMemory(placement, 0, page_size, {page_bytes(0), page_bytes(2)}, 2)};
  csp::Channel<Packet> injection{"injection", 4};
  std::vector<csp::Channel<Packet>> ports;
  std::vector<std::unique_ptr<nodes::WorkerPort>> in;
  std::vector<std::unique_ptr<nodes::Outbox>> out;

  ScriptedSvm() {
    for (int w = 0; w < 2; ++w) {
      const auto port = static_cast<std::uint16_t>(Ports::first_worker + w);
      ports.emplace_back("port " + std::to_string(port), 4);
      in.push_back(std::make_unique<nodes::WorkerPort>(ports.back().reader()));
      out.push_back(std::make_unique<nodes::Outbox>(injection.writer(), port, 8));
      svm.add_worker(nodes::make_page_fetch(placement, port, *in.back(), *out.back()));
    }
  }
};

TEST(Svm, TwoMissesOfOnePageSendOneRequest) {
  ScriptedSvm s;
  bool second_asked = false;
  bool first_ok = false, second_ok = false, own_ok = false;
  csp::Runtime runtime(1);
  runtime.spawn("worker 0", 0, [&] {
    first_ok = holds_page(s.svm.worker(0).page(1), 1);
    own_ok = holds_page(s.svm.worker(0).page(2), 2);
  });
  runtime.spawn("worker 1", 0, [&] {
    second_asked = true;  // page() runs on to its wait without a switch: one thread
    second_ok = holds_page(s.svm.worker(1).page(1), 1);
  });
  runtime.spawn("owner of page 1", 0, [&] {
    const Packet asked = s.injection.reader().read();
    EXPECT_EQ(static_cast<MessageKind>(asked.kind), MessageKind::page_request);
    EXPECT_EQ(asked.destination, 1u);
    EXPECT_EQ(asked.port, Ports::page_server);
    const nodes::PageRequest r = nodes::decode_page_request(asked.payload);
    EXPECT_EQ(r.page, 1u);
    EXPECT_EQ(r.reply_port, Ports::first_worker);
    while (!second_asked) csp::yield();
    const auto bytes = page_bytes(1);
    s.ports[0].writer().write(
        nodes::make_packet(0, r.reply_port, MessageKind::page_reply, nodes::encode_page_reply(1, bytes)));
  });
  runtime.run();
  EXPECT_TRUE(first_ok);
  EXPECT_TRUE(second_ok);
  EXPECT_TRUE(own_ok);
  EXPECT_FALSE(s.injection.reader().try_read().has_value());  // one request in all
  EXPECT_EQ(s.svm.worker(0).stats().misses, 1u);
  EXPECT_EQ(s.svm.worker(0).stats().own_hits, 1u);
  EXPECT_EQ(s.svm.worker(1).stats().coalesced, 1u);
  EXPECT_EQ(s.svm.worker(1).stats().misses, 0u);
  const nodes::SvmStats total = s.svm.stats();
  EXPECT_EQ(total.accesses(), 3u);
}

// Once fetched, the page is the node's: another worker's access is a cache
// hit, with no request.
TEST(Svm, AFetchedPageIsACacheHitForEveryWorker) {
  ScriptedSvm s;
  csp::Runtime runtime(1);
  runtime.spawn("worker 0 then 1", 0, [&] {
    EXPECT_TRUE(holds_page(s.svm.worker(0).page(3), 3));
    EXPECT_TRUE(holds_page(s.svm.worker(1).page(3), 3));
    EXPECT_TRUE(holds_page(s.svm.worker(0).page(3), 3));
  });
  runtime.spawn("owner of page 3", 0, [&] {
    const nodes::PageRequest r = nodes::decode_page_request(s.injection.reader().read().payload);
    EXPECT_EQ(r.page, 3u);
    s.ports[0].writer().write(
        nodes::make_packet(0, r.reply_port, MessageKind::page_reply, nodes::encode_page_reply(3, page_bytes(3))));
  });
  runtime.run();
  EXPECT_FALSE(s.injection.reader().try_read().has_value());
  EXPECT_EQ(s.svm.stats().misses, 1u);
  EXPECT_EQ(s.svm.stats().cache_hits, 2u);
}

}  // namespace
