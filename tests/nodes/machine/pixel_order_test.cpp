// Item orders: the Hilbert order visits every position of the frame exactly
// once, in steps of one cell, and keeps runs of items compact.
#include "nodes/machine/pixel_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

using nodes::item_positions;
using nodes::PixelOrder;

struct Cell {
  int x, y;
};

Cell cell(std::uint32_t position, int width) {
  return {static_cast<int>(position % static_cast<std::uint32_t>(width)),
          static_cast<int>(position / static_cast<std::uint32_t>(width))};
}

TEST(PixelOrder, ScanlineIsTheIdentityAndNeedsNoTable) {
  EXPECT_TRUE(item_positions(7, 5, PixelOrder::scanline).empty());
}

// Every cell exactly once, each step to a neighbour (diagonal only where a side is odd).
void expect_every_cell_once_in_single_steps(int width, int height) {
  const auto positions = item_positions(width, height, PixelOrder::hilbert);
  ASSERT_EQ(positions.size(), static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
      << width << "x" << height;
  std::vector<int> seen(positions.size(), 0);
  for (std::size_t k = 0; k < positions.size(); ++k) {
    ASSERT_LT(positions[k], positions.size()) << width << "x" << height;
    ASSERT_EQ(++seen[positions[k]], 1) << width << "x" << height << " position " << positions[k];
    if (k == 0) continue;
    const Cell a = cell(positions[k - 1], width), b = cell(positions[k], width);
    const int dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
    ASSERT_LE(std::max(dx, dy), 1) << width << "x" << height << " item " << k;
    if (dx + dy == 2) {
      ASSERT_TRUE(width % 2 != 0 || height % 2 != 0) << width << "x" << height << " item " << k;
    }
  }
}

TEST(PixelOrder, HilbertVisitsEveryCellOnceInSingleSteps) {
  for (int width = 1; width <= 40; ++width)
    for (int height = 1; height <= 40; ++height) expect_every_cell_once_in_single_steps(width, height);
}

// Frames far larger than the walks the order keeps and replays, so that
// replayed pieces are joined by the recursion above them.
TEST(PixelOrder, HilbertOnLargeFramesVisitsEveryCellOnceInSingleSteps) {
  for (const auto& [width, height] : {std::pair{512, 512}, {300, 200}, {257, 131}, {131, 257}, {1000, 3}, {97, 4099}})
    expect_every_cell_once_in_single_steps(width, height);
}

TEST(PixelOrder, HilbertOnAPowerOfTwoSquareIsTheClassicCurve) {
  for (int side : {2, 4, 8, 64}) {
    const auto positions = item_positions(side, side, PixelOrder::hilbert);
    // Starts and ends at the two bottom corners of the first row.
    EXPECT_EQ(cell(positions.front(), side).x, 0);
    EXPECT_EQ(cell(positions.front(), side).y, 0);
    EXPECT_EQ(cell(positions.back(), side).x, side - 1);
    EXPECT_EQ(cell(positions.back(), side).y, 0);
    // Every aligned run of 4^k items fills a 2^k x 2^k square.
    for (int block = 2; block <= side; block *= 2) {
      const auto run = static_cast<std::size_t>(block * block);
      for (std::size_t first = 0; first < positions.size(); first += run) {
        int min_x = side, max_x = -1, min_y = side, max_y = -1;
        for (std::size_t k = first; k < first + run; ++k) {
          const Cell c = cell(positions[k], side);
          min_x = std::min(min_x, c.x), max_x = std::max(max_x, c.x);
          min_y = std::min(min_y, c.y), max_y = std::max(max_y, c.y);
        }
        ASSERT_EQ(max_x - min_x + 1, block) << side << " run at " << first;
        ASSERT_EQ(max_y - min_y + 1, block) << side << " run at " << first;
        ASSERT_EQ(min_x % block, 0);
        ASSERT_EQ(min_y % block, 0);
      }
    }
  }
}

TEST(PixelOrder, HilbertRunsAreCompactOnAnOddFrame) {
  // A run of 64 items on a 300x200 frame stays within a small box, where a
  // scanline run would be 64 pixels long.
  const int width = 300, height = 200;
  const auto positions = item_positions(width, height, PixelOrder::hilbert);
  for (std::size_t first = 0; first + 64 <= positions.size(); first += 64) {
    int min_x = width, max_x = -1, min_y = height, max_y = -1;
    for (std::size_t k = first; k < first + 64; ++k) {
      const Cell c = cell(positions[k], width);
      min_x = std::min(min_x, c.x), max_x = std::max(max_x, c.x);
      min_y = std::min(min_y, c.y), max_y = std::max(max_y, c.y);
    }
    ASSERT_LE((max_x - min_x + 1) * (max_y - min_y + 1), 4 * 64) << "run at " << first;
  }
}

TEST(PixelOrder, NamesAndEmptyFrames) {
  EXPECT_STREQ(nodes::pixel_order_name(PixelOrder::scanline), "scanline");
  EXPECT_STREQ(nodes::pixel_order_name(PixelOrder::hilbert), "hilbert");
  EXPECT_THROW(item_positions(0, 5, PixelOrder::hilbert), std::invalid_argument);
  EXPECT_THROW(item_positions(5, 0, PixelOrder::scanline), std::invalid_argument);
}

}  // namespace
