// The farmer driven through its own channels by a test process playing a
// worker and a page server: P + 1 answers to a work request (work while the
// plan has tiles, then stop), one answer per result and the result passed
// to the collector, server_stop only after the last worker_done, and the
// end (on_quiet) only after server_done.
#include "nodes/machine/farmer.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "csp/csp.hpp"

namespace {

using nodes::MessageKind;
using nodes::Packet;
using nodes::Ports;
using nodes::Tile;

constexpr std::uint16_t worker_port = Ports::first_worker;

MessageKind kind_of(const Packet& p) { return static_cast<MessageKind>(p.kind); }

// A packet as the network delivers it: from node 0, to the farmer.
Packet from_worker(MessageKind kind, nodes::Payload payload = {}) {
  Packet p = nodes::make_packet(0, Ports::farmer, kind, std::move(payload));
  p.source = 0;
  return p;
}

Packet result_for(Tile tile) {
  const std::vector<tracer::Color> colours(tile.count, tracer::Color{0.5f, 0.25f, 1.0f});
  return from_worker(MessageKind::result, nodes::encode_result(worker_port, tile, colours));
}

// One node of one worker, 8 items in tiles of 4: two tiles in the plan.
struct ScriptedFarmer {
  nodes::WorkPlan plan{8, 4, nodes::Schedule::dynamic, 1, 1};
  csp::Channel<Packet> in{"farmer in", 16}, out{"farmer out", 16}, collector{"results", 16};
  nodes::FarmerCounters counters;
  bool quiet = false;

  nodes::Farmer farmer() {
    return nodes::Farmer(
        plan, 1, 1, in.reader(), nodes::Outbox(out.writer(), 0, 1), collector.writer(), [this] { quiet = true; },
        counters);
  }
};

TEST(Farmer, AnswersEveryTileAskedForThenStopsTheServers) {
  ScriptedFarmer s;
  csp::Runtime runtime(1);
  runtime.spawn("farmer", 0, [&s] { s.farmer().run(); });
  runtime.spawn("worker and server", 0, [&s] {
    auto in = s.in.writer();
    auto out = s.out.reader();
    // P + 1 = 3 answers: both tiles of the plan, then stop.
    in.write(from_worker(MessageKind::work_request, nodes::encode_work_request({worker_port, 3})));
    std::vector<Tile> tiles;
    for (int i = 0; i < 2; ++i) {
      const Packet answer = out.read();
      ASSERT_EQ(kind_of(answer), MessageKind::work);
      EXPECT_EQ(answer.destination, 0u);
      EXPECT_EQ(answer.port, worker_port);
      tiles.push_back(nodes::decode_tile(answer.payload));
    }
    EXPECT_EQ(tiles[0], (Tile{0, 4}));
    EXPECT_EQ(tiles[1], (Tile{4, 4}));
    EXPECT_EQ(kind_of(out.read()), MessageKind::stop);

    // Each result is answered (stop: the plan is done) and passed on.
    for (const Tile& tile : tiles) {
      in.write(result_for(tile));
      EXPECT_EQ(kind_of(out.read()), MessageKind::stop);
      const Packet passed = s.collector.reader().read();
      EXPECT_EQ(nodes::decode_result(passed.payload).tile, tile);
    }
    // The farmer has read everything sent so far: no server_stop yet.
    EXPECT_FALSE(out.try_read().has_value());

    in.write(from_worker(MessageKind::worker_done));
    const Packet stop = out.read();
    EXPECT_EQ(kind_of(stop), MessageKind::server_stop);
    EXPECT_EQ(stop.destination, 0u);
    EXPECT_EQ(stop.port, Ports::page_server);
    EXPECT_FALSE(s.quiet);  // the page server has not answered

    in.write(from_worker(MessageKind::server_done));
  });
  runtime.run();
  EXPECT_TRUE(s.quiet);
  EXPECT_EQ(s.counters.tiles, 2u);
  EXPECT_EQ(s.counters.items, 8u);
  EXPECT_EQ(s.counters.stops, 3u);
  EXPECT_EQ(s.counters.results, 2u);
}

// Done with results missing: a protocol error, not a quiet end.
TEST(Farmer, RefusesToEndWithItemsMissing) {
  ScriptedFarmer s;
  csp::Runtime runtime(1);
  runtime.spawn("farmer", 0, [&s] { s.farmer().run(); });
  runtime.spawn("worker and server", 0, [&s] {
    s.in.writer().write(from_worker(MessageKind::worker_done));
    s.in.writer().write(from_worker(MessageKind::server_done));
  });
  try {
    runtime.run();
    ADD_FAILURE() << "no error";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("results cover 0 of 8 items"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(s.quiet);
}

TEST(Farmer, RefusesAMessageMeantForAnotherProcess) {
  ScriptedFarmer s;
  csp::Runtime runtime(1);
  runtime.spawn("farmer", 0, [&s] { s.farmer().run(); });
  runtime.spawn("worker", 0, [&s] { s.in.writer().write(from_worker(MessageKind::page_reply)); });
  EXPECT_THROW(runtime.run(), std::logic_error);
}

}  // namespace
