// Plots as PNG pictures: the size asked for, data drawn where the geometry
// puts it, anti-aliased text in the title area, legends only where they
// name something, and size limits.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "app/viz/plot_geometry.hpp"
#include "app/viz/plot_raster.hpp"
#include "picture_check.hpp"

namespace viz {
namespace {

LinePlot miss_ratio_plot() {
  LinePlot p;
  p.title = "rings4 on hypercube: miss ratio against cache size";
  p.series.push_back({"hypercube", {{1, 0.5}, {2, 0.25}, {4, 0.1}}});
  return p;
}

TEST(PlotImage, DrawsSeriesWhereTheGeometrySays) {
  const LinePlot p = miss_ratio_plot();
  const tracer::Image img = plot_image(p, 400, 300);
  ASSERT_EQ(img.width(), 400);
  ASSERT_EQ(img.height(), 300);
  const detail::PlotGeometry g(p, {0, 0, 400, 300});
  const tracer::Rgb8Image bytes = img.to_rgb8();
  // The pixel under each point is inside its marker, so wholly of its colour.
  for (const Point& pt : g.pixels(p.series[0]))
    EXPECT_TRUE(test::near(test::pixel(bytes, static_cast<int>(pt.x), static_cast<int>(pt.y)), series_colour(0)))
        << pt.x << ", " << pt.y;
}

TEST(PlotImage, TitleIsAntialiasedText) {
  LinePlot p = miss_ratio_plot();
  const detail::PlotGeometry g(p, {0, 0, 640, 420});
  const int title_bottom = static_cast<int>(g.area().top) - 2;
  const tracer::Rgb8Image titled = plot_image(p).to_rgb8();
  EXPECT_GT(test::dark_pixels(titled, 0, 0, 640, title_bottom), 100);
  EXPECT_GT(test::intermediate_greys(titled, 0, 0, 640, title_bottom), 50);
  p.title.clear();
  const tracer::Rgb8Image untitled = plot_image(p).to_rgb8();
  EXPECT_EQ(test::dark_pixels(untitled, 0, 0, 640, 6), 0);  // above the top tick value
}

TEST(PlotImage, AxisTextIsAntialiased) {
  const LinePlot p = miss_ratio_plot();
  const detail::PlotGeometry g(p, {0, 0, 640, 420});
  const tracer::Rgb8Image bytes = plot_image(p).to_rgb8();
  // Left of the data area: the y tick values.
  const int x1 = static_cast<int>(g.area().left) - 2;
  EXPECT_GT(test::dark_pixels(bytes, 0, static_cast<int>(g.area().top), x1, static_cast<int>(g.area().bottom())), 20);
  EXPECT_GT(test::intermediate_greys(bytes, 0, static_cast<int>(g.area().top), x1, static_cast<int>(g.area().bottom())),
            20);
}

// A single series needs no legend (the title names it); a labelled
// threshold still gets one, outside the data area.
TEST(PlotImage, LegendOnlyWhereItNamesSomething) {
  LinePlot p = miss_ratio_plot();
  EXPECT_EQ(detail::PlotGeometry(p, {0, 0, 400, 300}).legend().width, 0);
  p.series.push_back({"ring", {{1, 0.6}, {4, 0.2}}});
  const detail::PlotGeometry two(p, {0, 0, 400, 300});
  EXPECT_GT(two.legend().width, 0);
  EXPECT_TRUE(two.legend_lists_series());
  const tracer::Rgb8Image bytes = plot_image(p, 400, 300).to_rgb8();
  const detail::Rect& l = two.legend();
  EXPECT_GT(test::dark_pixels(bytes, static_cast<int>(l.left) + 28, static_cast<int>(l.top),
                              static_cast<int>(l.right()), static_cast<int>(l.bottom())),
            10);

  LinePlot one = miss_ratio_plot();
  one.thresholds.push_back({0.3, "50% threshold"});
  const detail::PlotGeometry g(one, {0, 0, 400, 300});
  EXPECT_GT(g.legend().width, 0);
  EXPECT_FALSE(g.legend_lists_series());
  EXPECT_GE(g.legend().left, g.area().right());
}

TEST(PlotImage, PointsThatCannotBeDrawnAreSkipped) {
  LinePlot p;
  p.x_scale = AxisScale::log2;
  p.series.push_back({"s", {{0, 1}, {1, std::nan("")}, {2, 3}, {std::numeric_limits<double>::infinity(), 1}, {4, 5}}});
  const detail::PlotGeometry g(p, {0, 0, 400, 300});
  ASSERT_EQ(g.pixels(p.series[0]).size(), 2u);
  const tracer::Rgb8Image bytes = plot_image(p, 400, 300).to_rgb8();
  for (const Point& pt : g.pixels(p.series[0]))
    EXPECT_TRUE(test::near(test::pixel(bytes, static_cast<int>(pt.x), static_cast<int>(pt.y)), series_colour(0)));
}

TEST(PlotImage, RejectsSillySizes) {
  EXPECT_THROW(plot_image(LinePlot{}, 10, 300), std::invalid_argument);
  EXPECT_THROW(plot_image(LinePlot{}, 400, 100000), std::invalid_argument);
  EXPECT_NO_THROW(plot_image(LinePlot{}, 64, 64));
}

}  // namespace
}  // namespace viz
