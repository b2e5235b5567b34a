// The farmer's tile plan and the collector's frame bookkeeping, without
// fibers: every item handed out and received exactly once.
#include "nodes/frame_assembler.hpp"
#include "nodes/work_plan.hpp"

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

TEST(WorkPlan, ZeroGrainIsRejectedNamingTheOption) {
  try {
    WorkPlan(10, 0, Schedule::dynamic, 1, 1);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--grain"), std::string::npos);
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

TEST(Messages, TruncatedPayloadIsRejected) {
  auto payload = nodes::encode_result(5, {0, 2}, std::vector<tracer::Color>(2));
  payload.pop_back();
  EXPECT_THROW(nodes::decode_result(payload), std::runtime_error);
  EXPECT_THROW(nodes::decode_tile(std::vector<std::byte>(3)), std::runtime_error);
}

}  // namespace
