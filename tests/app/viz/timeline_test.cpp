// Tile timelines: one bar per tile, placed by its times and coloured by page
// requests per item, sub-pixel tiles of one worker merged into bars of about
// a pixel, lanes of several workers parted and named, every surface valid,
// and clear errors for tiles outside the machine or with impossible times.
#include "app/viz/timeline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "picture_check.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

Timeline busy_machine() {
  Timeline t{"teapot <hypercube> & co", "wall time (s)", 8, 2, {}};
  for (int n = 0; n < 8; ++n)
    for (int w = 0; w < 2; ++w)
      for (int k = 0; k < 3; ++k)
        t.tiles.push_back({n, w, static_cast<std::uint32_t>(100 * n + 10 * w + k), 4, 1.0 * k, 1.0 * k + 0.9,
                           static_cast<std::uint64_t>(n + k)});
  return t;
}

TEST(Timeline, OneBarPerTileOnEverySurface) {
  const Timeline t = busy_machine();
  EXPECT_EQ(timeline_bars(t).size(), t.tiles.size());
  const std::string svg = timeline_svg(t);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::first_non_finite_attribute(doc), "");
  EXPECT_TRUE(test::is_pdf(timeline_pdf(t)));
  // Each bar is drawn in its colour: the pixel at its middle.
  const tracer::Rgb8Image img = timeline_image(t).to_rgb8();
  for (const TimelineBar& b : timeline_bars(t))
    EXPECT_TRUE(
        test::near(test::pixel(img, static_cast<int>(b.x + b.width / 2), static_cast<int>(b.y + b.height / 2)), b.fill))
        << "node " << b.node << " worker " << b.worker;
}

// The axis runs from 0 to a round number at or above the last end: with the
// last tile ending at 10 s a tile of [0, 5] s covers the left half of the
// plot, and the tile with most page requests per item takes the top colour.
TEST(Timeline, BarsFollowTheirTimesAndRequestsPerItem) {
  Timeline t{"", "s", 2, 1, {{0, 0, 0, 10, 0.0, 5.0, 0}, {1, 0, 10, 10, 5.0, 10.0, 30}, {1, 0, 20, 10, 2.0, 4.0, 15}}};
  const std::vector<TimelineBar> b = timeline_bars(t);
  ASSERT_EQ(b.size(), 3u);
  // Bars come lane by lane in order of start: node 0's, then node 1's from 2 s and from 5 s.
  EXPECT_EQ(b[1].start, 2.0);
  EXPECT_NEAR(b[0].width, b[2].width, 1e-9);
  EXPECT_NEAR(b[0].x + b[0].width, b[2].x, 1e-9);
  EXPECT_NEAR(b[1].width, 0.4 * b[0].width, 1e-9);
  EXPECT_LT(b[0].y, b[1].y);  // node 0 above node 1
  EXPECT_EQ(b[0].fill, work_scale(0.0));
  EXPECT_EQ(b[1].fill, work_scale(0.5));
  EXPECT_EQ(b[2].fill, work_scale(1.0));
}

// 1000 tiles of 1 ms back to back in one lane, on an axis of 10 s (about 67
// pixels a second): about 15 tiles to a bar of a pixel (the last may be
// less), the bars together as wide as the second they cover. A gap and
// another worker's lane start bars of their own, drawn half a pixel wide.
TEST(Timeline, SubPixelTilesOfOneWorkerShareBars) {
  Timeline t{"", "s", 1, 2, {}};
  for (int k = 0; k < 1000; ++k) t.tiles.push_back({0, 0, static_cast<std::uint32_t>(k), 1, k * 1e-3, (k + 1) * 1e-3, 1});
  t.tiles.push_back({0, 1, 1000, 1, 0.0, 1e-3, 0});
  t.tiles.push_back({0, 0, 1001, 1, 9.999, 10.0, 0});
  const std::vector<TimelineBar> b = timeline_bars(t);
  ASSERT_GE(b.size(), 3u);
  // Worker 0's bars come first, the one at 9.999 s last of them; worker 1's bar follows.
  const double pixels_per_second = (b[b.size() - 2].x - b.front().x) / 9.999;
  EXPECT_NEAR(pixels_per_second, 66.8, 0.5);
  EXPECT_GE(b.size(), 2u + 60u);
  EXPECT_LE(b.size(), 2u + 70u);
  double merged = 0;
  int tiles = 0;
  for (std::size_t i = 0; i + 2 < b.size(); ++i) {
    if (i + 3 < b.size()) {
      EXPECT_GE(b[i].width, 0.99) << i;
    }
    EXPECT_LE(b[i].width, 2.0) << i;
    merged += b[i].width;
    tiles += b[i].tiles;
  }
  EXPECT_EQ(tiles, 1000);
  EXPECT_NEAR(merged, pixels_per_second, 0.01);
  EXPECT_EQ(b[b.size() - 2].width, 0.5);
  EXPECT_EQ(b.back().width, 0.5);
  EXPECT_EQ(b.back().worker, 1);
}

// Two workers a node: a line parts the lanes, and each lane is named at the
// right of the plot; one worker a node: neither.
TEST(Timeline, LanesOfSeveralWorkersArePartedAndNamed) {
  auto picture = [](int workers) {
    Timeline t{"", "s", 2, workers, {}};
    t.tiles.push_back({0, 0, 0, 1, 0.0, 10.0, 0});  // spans the axis: its bar ends where the plot does
    return std::pair{timeline_image(t).to_rgb8(), timeline_bars(t).front()};
  };
  const auto [two, bar] = picture(2);
  const auto [one, single] = picture(1);
  const int plot_right = static_cast<int>(bar.x + bar.width);
  // Bars are inset by half a pixel in their lane: node 0's row starts half a
  // pixel above its first bar. Node 1's row has no tiles: between its lanes,
  // the parting line.
  const double row_top = bar.y - 0.5, lane_h = bar.height + 1.0;
  const int line_y = static_cast<int>(row_top + 3 * lane_h);
  const Rgb8 parted = test::pixel(two, plot_right - 50, line_y);
  const Rgb8 plain = test::pixel(one, plot_right - 50, line_y);
  EXPECT_LT(parted.r + 10, plain.r) << int(parted.r) << " vs " << int(plain.r);
  EXPECT_GT(test::dark_pixels(two, plot_right + 1, static_cast<int>(row_top), two.width,
                              static_cast<int>(row_top + 4 * lane_h), 160),
            5);
  EXPECT_EQ(test::dark_pixels(one, plot_right + 1, static_cast<int>(row_top), one.width,
                              static_cast<int>(row_top + 4 * lane_h), 160),
            0);
}

TEST(Timeline, RejectsTilesOutsideTheMachineOrTime) {
  const auto with = [](TimelineTile tile) { return Timeline{"", "s", 4, 2, {tile}}; };
  EXPECT_THROW(timeline_svg(with({4, 0, 0, 1, 0, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_image(with({0, 2, 0, 1, 0, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_pdf(with({0, 0, 0, 1, 2, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_bars(with({0, 0, 0, 1, -1, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_svg(with({0, 0, 0, 1, 0, std::numeric_limits<double>::quiet_NaN(), 0})),
               std::invalid_argument);
  EXPECT_THROW(timeline_svg(Timeline{"", "s", 0, 1, {}}), std::invalid_argument);
  EXPECT_TRUE(test::check_xml(timeline_svg(Timeline{"", "s", 3, 1, {}})).ok);  // nothing to draw yet
}

}  // namespace
}  // namespace viz
