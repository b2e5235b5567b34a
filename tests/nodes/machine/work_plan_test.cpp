// The farmer's tile plan and the collector's frame bookkeeping, without
// fibers: every item handed out and received exactly once.
#include "nodes/machine/frame_assembler.hpp"
#include "nodes/machine/work_plan.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using nodes::Schedule;
using nodes::Tile;
using nodes::WorkPlan;

std::vector<int> coverage(WorkPlan& plan, int nodes, int workers) {
  std::vector<int> times(plan.items(), 0);
  bool any = true;
  while (any) {
    any = false;
    for (int n = 0; n < nodes; ++n)
      for (int w = 0; w < workers; ++w)
        if (auto tile = plan.next(n, w)) {
          any = true;
          for (std::uint32_t i = 0; i < tile->count; ++i) ++times[tile->first + i];
        }
  }
  return times;
}

TEST(WorkPlan, DynamicHandsEveryItemOnceInGrainSizedTiles) {
  WorkPlan plan(103, 4, Schedule::dynamic, 3, 2);
  EXPECT_EQ(plan.next(0, 0), (Tile{0, 4}));
  EXPECT_EQ(plan.next(2, 1), (Tile{4, 4}));
  const auto times = coverage(plan, 3, 2);
  for (std::uint32_t i = 8; i < 103; ++i) ASSERT_EQ(times[i], 1) << i;
  EXPECT_EQ(plan.handed_out(), 103u);
  EXPECT_FALSE(plan.next(1, 0));
}

TEST(WorkPlan, StaticGivesEachWorkerOneShareThenStop) {
  WorkPlan plan(100, 1, Schedule::static_split, 3, 2);
  const auto first = plan.next(0, 0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->first, 0u);
  EXPECT_FALSE(plan.next(0, 0));
  const auto times = coverage(plan, 3, 2);
  for (std::uint32_t i = first->count; i < 100; ++i) ASSERT_EQ(times[i], 1) << i;
  EXPECT_EQ(plan.handed_out(), 100u);
}

TEST(WorkPlan, StaticWithMoreWorkersThanItemsStopsTheIdleOnes) {
  WorkPlan plan(3, 1, Schedule::static_split, 4, 2);
  const auto times = coverage(plan, 4, 2);
  for (int t : times) EXPECT_EQ(t, 1);
}

// Requests in a fixed pseudo-random order, as the network might deliver them.
std::vector<int> coverage_shuffled(WorkPlan& plan, int nodes, int workers, unsigned seed) {
  std::vector<int> times(plan.items(), 0);
  std::vector<bool> stopped(static_cast<std::size_t>(nodes * workers), false);
  int running = nodes * workers;
  while (running > 0) {
    seed = seed * 1103515245u + 12345u;
    const int who = static_cast<int>((seed >> 8) % static_cast<unsigned>(nodes * workers));
    if (stopped[static_cast<std::size_t>(who)]) continue;
    if (auto tile = plan.next(who / workers, who % workers)) {
      for (std::uint32_t i = 0; i < tile->count; ++i) ++times[tile->first + i];
    } else {
      stopped[static_cast<std::size_t>(who)] = true;
      --running;
    }
  }
  return times;
}

TEST(WorkPlan, AffinityHandsEveryItemOnceWhateverTheOrderOfRequests) {
  for (unsigned seed : {1u, 7u, 99u}) {
    WorkPlan plan(1000, 3, Schedule::affinity, 5, 2);
    const auto times = coverage_shuffled(plan, 5, 2, seed);
    for (std::uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(times[i], 1) << "item " << i << " seed " << seed;
    EXPECT_EQ(plan.handed_out(), 1000u);
    EXPECT_GT(plan.steals(), 0u) << seed;
  }
}

TEST(WorkPlan, AffinityStartsEachWorkerOnItsOwnShareInShrinkingTiles) {
  // 16 workers with shares of 100 items: tiles are 1/16 of what is left, at
  // least the grain.
  WorkPlan plan(1600, 2, Schedule::affinity, 8, 2);
  EXPECT_EQ(plan.next(3, 1), (Tile{700, 7}));  // ceil(100 / 16)
  EXPECT_EQ(plan.next(3, 1), (Tile{707, 6}));  // ceil(93 / 16)
  EXPECT_EQ(plan.next(0, 0), (Tile{0, 7}));
  std::uint32_t last = 0;
  for (auto tile = plan.next(0, 0); tile && tile->first < 100; tile = plan.next(0, 0)) {
    EXPECT_GE(tile->count, 2u);
    last = tile->first + tile->count;
  }
  EXPECT_EQ(last, 100u);  // worker (0, 0) went through its share in order
}

TEST(WorkPlan, AffinityStealsFromTheBackOfTheLargestShare) {
  WorkPlan plan(64, 1, Schedule::affinity, 4, 1);  // shares of 16
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(plan.next(0, 0));
  EXPECT_EQ(plan.next(2, 0), (Tile{32, 1}));  // node 2 leaves 15 items in its share
  // Node 0's share is gone: it takes 1/16 of node 1's (the first of the
  // largest), from the far end.
  EXPECT_EQ(plan.next(0, 0), (Tile{31, 1}));
  EXPECT_EQ(plan.steals(), 1u);
  EXPECT_EQ(plan.next(1, 0), (Tile{16, 1}));  // node 1 goes on at its front
}

// A worker asking ahead takes nothing of a share whose owner has not asked
// yet but that share's first tile: with shares of one tile (small frames on
// many processors) it would otherwise leave their owners idle.
TEST(WorkPlan, AffinityLeavesEachOwnerItsFirstTile) {
  WorkPlan plan(64, 16, Schedule::affinity, 4, 1);  // shares of one tile
  EXPECT_EQ(plan.next(0, 0), (Tile{0, 16}));
  EXPECT_FALSE(plan.next(0, 0));
  for (std::uint32_t n = 1; n < 4; ++n) EXPECT_EQ(plan.next(static_cast<int>(n), 0), (Tile{16 * n, 16}));
  EXPECT_EQ(plan.steals(), 0u);

  WorkPlan larger(96, 16, Schedule::affinity, 2, 1);  // shares of three tiles
  for (std::uint32_t first : {0u, 16u, 32u}) EXPECT_EQ(larger.next(0, 0), (Tile{first, 16}));
  EXPECT_EQ(larger.next(0, 0), (Tile{80, 16}));  // from the back of node 1's share
  EXPECT_EQ(larger.next(0, 0), (Tile{64, 16}));
  EXPECT_FALSE(larger.next(0, 0));              // node 1's first tile stays
  EXPECT_EQ(larger.next(1, 0), (Tile{48, 16}));
  EXPECT_FALSE(larger.next(1, 0));
  EXPECT_EQ(larger.steals(), 2u);
}

TEST(WorkPlan, ZeroGrainIsRejectedNamingTheField) {
  try {
    WorkPlan(10, 0, Schedule::dynamic, 1, 1);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("grain must be at least 1"), std::string::npos);
  }
}

TEST(FrameAssembler, StoresColoursBitExactAndRejectsDuplicates) {
  nodes::FrameAssembler frame(4);
  const std::vector<tracer::Color> colors{{0.1f, 0.2f, 0.3f}, {1e-30f, -0.0f, 7.0f}};
  const auto payload = nodes::encode_result(5, {1, 2}, colors);
  frame.add(nodes::decode_result(payload));
  EXPECT_EQ(frame.received(), 2u);
  EXPECT_FALSE(frame.complete());
  EXPECT_EQ(frame.colors()[2], colors[1]);
  EXPECT_THROW(frame.add(nodes::decode_result(payload)), std::logic_error);
  const auto beyond = nodes::encode_result(5, {3, 2}, colors);
  EXPECT_THROW(frame.add(nodes::decode_result(beyond)), std::logic_error);
  // A view whose colours do not fill its tile is refused, not read past.
  const std::vector<std::byte> short_rgb(sizeof(tracer::Color));
  EXPECT_THROW(frame.add(nodes::ResultView{5, {0, 2}, short_rgb}), std::logic_error);
  EXPECT_EQ(frame.received(), 2u);
}

TEST(FrameAssembler, PutsItemsOfAPixelOrderInTheirScanlinePlaces) {
  const std::vector<std::uint32_t> positions{2, 0, 3, 1};  // item k lies at scanline position positions[k]
  nodes::FrameAssembler frame(4, positions);
  const std::vector<tracer::Color> colors{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  frame.add(nodes::decode_result(nodes::encode_result(5, {0, 3}, colors)));
  EXPECT_EQ(frame.colors()[2], colors[0]);
  EXPECT_EQ(frame.colors()[0], colors[1]);
  EXPECT_EQ(frame.colors()[3], colors[2]);
  EXPECT_FALSE(frame.complete());
  // Item 1 again: a duplicate, though scanline position 1 is still empty.
  const std::vector<tracer::Color> one{colors[0]};
  EXPECT_THROW(frame.add(nodes::decode_result(nodes::encode_result(5, {1, 1}, one))), std::logic_error);
  frame.add(nodes::decode_result(nodes::encode_result(5, {3, 1}, one)));
  EXPECT_EQ(frame.colors()[1], colors[0]);
  EXPECT_TRUE(frame.complete());
  EXPECT_THROW(nodes::FrameAssembler(5, positions), std::logic_error);
}

TEST(Messages, PayloadsRoundTrip) {
  const auto work_request = nodes::decode_work_request(nodes::encode_work_request({7, 3}));
  EXPECT_EQ(work_request.reply_port, 7);
  EXPECT_EQ(work_request.tiles, 3);
  const std::vector<tracer::Color> colors{{0.5f, 0.25f, 1.0f}};
  const auto result_payload = nodes::encode_result(9, {4, 1}, colors);
  const auto result = nodes::decode_result(result_payload);
  EXPECT_EQ(result.reply_port, 9);
  EXPECT_EQ(result.tile, (Tile{4, 1}));
  EXPECT_EQ(result.color(0), colors[0]);
  EXPECT_EQ(nodes::decode_tile(nodes::encode_tile({12, 34})), (Tile{12, 34}));
  const auto request = nodes::decode_page_request(nodes::encode_page_request({99, 5}));
  EXPECT_EQ(request.page, 99u);
  EXPECT_EQ(request.reply_port, 5);
  const std::vector<std::byte> bytes{std::byte{1}, std::byte{2}, std::byte{3}};
  const auto reply = nodes::encode_page_reply(42, bytes);
  EXPECT_EQ(nodes::page_reply_id(reply), 42u);
  const auto back = nodes::page_reply_bytes(reply);
  EXPECT_EQ(std::vector<std::byte>(back.begin(), back.end()), bytes);
}

// A reply that points at the owner's page reads as the copy does, counts
// the copy's bytes, and becomes the copy when its shared bytes are sent on
// as payload (as the bridge sends them to another process).
TEST(Messages, ASharedPageReplyIsTheCopyByReference) {
  const std::vector<std::byte> page{std::byte{7}, std::byte{8}, std::byte{9}, std::byte{10}};
  const nodes::Packet shared = nodes::make_page_reply(3, 5, 42, page);
  EXPECT_EQ(shared.port, 5);
  EXPECT_EQ(nodes::page_reply_id(shared), 42u);
  EXPECT_EQ(nodes::page_reply_bytes(shared).data(), page.data());
  EXPECT_EQ(shared.bytes(), nodes::encode_page_reply(42, page).size());
  nodes::Packet sent = shared;
  sent.payload.insert(sent.payload.end(), shared.shared.begin(), shared.shared.end());
  sent.shared = {};
  EXPECT_EQ(sent.payload, nodes::encode_page_reply(42, page));
  const auto back = nodes::page_reply_bytes(sent);
  EXPECT_EQ(std::vector<std::byte>(back.begin(), back.end()), page);
  nodes::Packet malformed = shared;
  malformed.payload.push_back(std::byte{0});
  EXPECT_THROW(nodes::page_reply_bytes(malformed), std::runtime_error);
}

TEST(Messages, TruncatedPayloadIsRejected) {
  auto payload = nodes::encode_result(5, {0, 2}, std::vector<tracer::Color>(2));
  payload.pop_back();
  EXPECT_THROW(nodes::decode_result(payload), std::runtime_error);
  EXPECT_THROW(nodes::decode_tile(std::vector<std::byte>(3)), std::runtime_error);
}

}  // namespace
