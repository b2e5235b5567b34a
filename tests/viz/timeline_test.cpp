// Tile timelines: well-formed SVG with one row per node and one bar per
// tile, bars placed by their times and coloured by page requests per item,
// sub-pixel tiles of one worker merged into bars of about a pixel, and clear
// errors for tiles outside the machine or with impossible times.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "app/viz/timeline.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

std::vector<const test::XmlElement*> bars(const test::XmlCheck& doc) {
  std::vector<const test::XmlElement*> out;
  for (const auto& e : doc.elements)
    if (e.attrs.count("class") && e.attrs.at("class") == "tile") out.push_back(&e);
  return out;
}

TEST(Timeline, OneRowPerNodeAndOneBarPerTile) {
  Timeline t{"teapot <hypercube> & co", "wall time (s)", 8, 2, {}};
  for (int n = 0; n < 8; ++n)
    for (int w = 0; w < 2; ++w)
      for (int k = 0; k < 3; ++k)
        t.tiles.push_back({n, w, static_cast<std::uint32_t>(100 * n + 10 * w + k), 4, 1.0 * k, 1.0 * k + 0.9,
                           static_cast<std::uint64_t>(n + k)});
  const std::string svg = timeline_svg(t);
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::count_class(doc, "row"), 8u);
  EXPECT_EQ(test::count_class(doc, "tile"), t.tiles.size());
  EXPECT_NE(svg.find("teapot &lt;hypercube&gt; &amp; co"), std::string::npos);
  for (const auto& e : doc.elements)
    for (const auto& [k, v] : e.attrs) {
      EXPECT_EQ(v.find("nan"), std::string::npos) << k;
      EXPECT_EQ(v.find("inf"), std::string::npos) << k;
    }
}

// The axis runs from 0 to a round number at or above the last end: with the
// last tile ending at 10 s a tile of [0, 5] s covers the left half of the
// plot, and the tile with most page requests per item takes the top colour.
TEST(Timeline, BarsFollowTheirTimesAndRequestsPerItem) {
  Timeline t{"", "s", 2, 1, {{0, 0, 0, 10, 0.0, 5.0, 0}, {1, 0, 10, 10, 5.0, 10.0, 30}, {1, 0, 20, 10, 2.0, 4.0, 15}}};
  const auto doc = test::check_xml(timeline_svg(t));
  ASSERT_TRUE(doc.ok) << doc.error;
  const auto b = bars(doc);
  ASSERT_EQ(b.size(), 3u);
  // Bars come lane by lane in order of start: node 0's, then node 1's from 2 s and from 5 s.
  const double x0 = std::stod(b[0]->attrs.at("x")), w0 = std::stod(b[0]->attrs.at("width"));
  const double x2 = std::stod(b[2]->attrs.at("x")), w2 = std::stod(b[2]->attrs.at("width"));
  EXPECT_NEAR(w0, w2, 0.02);
  EXPECT_NEAR(x0 + w0, x2, 0.02);
  EXPECT_NEAR(std::stod(b[1]->attrs.at("width")), 0.4 * w0, 0.02);
  EXPECT_LT(std::stod(b[0]->attrs.at("y")), std::stod(b[1]->attrs.at("y")));  // node 0 above node 1
  EXPECT_EQ(b[0]->attrs.at("fill"), hex(work_scale(0.0)));
  EXPECT_EQ(b[1]->attrs.at("fill"), hex(work_scale(0.5)));
  EXPECT_EQ(b[2]->attrs.at("fill"), hex(work_scale(1.0)));
}

// 1000 tiles of 1 ms back to back in one lane, on an axis of 10 s (about 67
// pixels a second): about 15 tiles to a bar of a pixel (the last may be
// less), the bars together as wide as the second they cover. A gap and another worker's lane start bars
// of their own, drawn half a pixel wide.
TEST(Timeline, SubPixelTilesOfOneWorkerShareBars) {
  Timeline t{"", "s", 1, 2, {}};
  for (int k = 0; k < 1000; ++k) t.tiles.push_back({0, 0, static_cast<std::uint32_t>(k), 1, k * 1e-3, (k + 1) * 1e-3, 1});
  t.tiles.push_back({0, 1, 1000, 1, 0.0, 1e-3, 0});
  t.tiles.push_back({0, 0, 1001, 1, 9.999, 10.0, 0});
  const auto doc = test::check_xml(timeline_svg(t));
  ASSERT_TRUE(doc.ok) << doc.error;
  const auto b = bars(doc);
  ASSERT_GE(b.size(), 3u);
  // Worker 0's bars come first, the one at 9.999 s last of them; worker 1's bar follows.
  const double pixels_per_second =
      (std::stod(b[b.size() - 2]->attrs.at("x")) - std::stod(b.front()->attrs.at("x"))) / 9.999;
  EXPECT_NEAR(pixels_per_second, 67.2, 0.1);
  EXPECT_GE(b.size(), 2u + 60u);
  EXPECT_LE(b.size(), 2u + 70u);
  double merged = 0;
  for (std::size_t i = 0; i + 2 < b.size(); ++i) {
    const double w = std::stod(b[i]->attrs.at("width"));
    if (i + 3 < b.size()) {
      EXPECT_GE(w, 0.99) << i;
    }
    EXPECT_LE(w, 2.0) << i;
    merged += w;
  }
  EXPECT_NEAR(merged, pixels_per_second, 0.4);  // widths are written to 0.01 px
  EXPECT_EQ(b[b.size() - 2]->attrs.at("width"), "0.5");
  EXPECT_EQ(b.back()->attrs.at("width"), "0.5");
}

TEST(Timeline, RejectsTilesOutsideTheMachineOrTime) {
  const auto with = [](TimelineTile tile) { return Timeline{"", "s", 4, 2, {tile}}; };
  EXPECT_THROW(timeline_svg(with({4, 0, 0, 1, 0, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_svg(with({0, 2, 0, 1, 0, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_svg(with({0, 0, 0, 1, 2, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_svg(with({0, 0, 0, 1, -1, 1, 0})), std::invalid_argument);
  EXPECT_THROW(timeline_svg(with({0, 0, 0, 1, 0, std::numeric_limits<double>::quiet_NaN(), 0})),
               std::invalid_argument);
  EXPECT_THROW(timeline_svg(Timeline{"", "s", 0, 1, {}}), std::invalid_argument);
  EXPECT_TRUE(test::check_xml(timeline_svg(Timeline{"", "s", 3, 1, {}})).ok);  // nothing to draw yet
}

}  // namespace
}  // namespace viz
