// Rasterised plots: the size asked for, data drawn where the geometry puts it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "app/viz/plot_geometry.hpp"
#include "app/viz/plot_raster.hpp"

namespace viz {
namespace {

TEST(PlotImage, DrawsSeriesWhereTheGeometrySays) {
  LinePlot p;
  p.title = "Miss ratio";
  p.series.push_back({"rings4", {{1, 0.5}, {2, 0.25}, {4, 0.1}}});
  const tracer::Image img = plot_image(p, 400, 300);
  ASSERT_EQ(img.width(), 400);
  ASSERT_EQ(img.height(), 300);
  const detail::PlotGeometry g(p, {0, 0, 400, 300}, 6.0);
  const Rgb8 c = series_colour(0);
  const tracer::Rgb8Image bytes = img.to_rgb8();
  for (const Point& pt : g.pixels(p.series[0])) {
    const std::size_t i = (static_cast<std::size_t>(pt.y + 0.5) * 400 + static_cast<std::size_t>(pt.x + 0.5)) * 3;
    EXPECT_EQ(bytes.rgb[i], c.r);
    EXPECT_EQ(bytes.rgb[i + 1], c.g);
    EXPECT_EQ(bytes.rgb[i + 2], c.b);
  }
}

// Nothing of the threshold's grey inside the data area but its line: the
// label is in the legend, not over the data.
TEST(PlotImage, ThresholdLabelIsInTheLegend) {
  LinePlot p;
  p.y_min = 0;
  p.y_max = 100;
  p.series.push_back({"hypercube", {{1, 100}, {64, 78}}});
  p.thresholds.push_back({50, "50% THRESHOLD"});
  const tracer::Image img = plot_image(p, 400, 300);
  const detail::PlotGeometry g(p, {0, 0, 400, 300}, 6.0);
  const tracer::Rgb8Image bytes = img.to_rgb8();
  auto grey_pixels = [&](const detail::Rect& r) {
    int n = 0;
    for (int y = static_cast<int>(r.top) + 1; y < static_cast<int>(r.bottom()); ++y)
      for (int x = static_cast<int>(r.left) + 1; x < static_cast<int>(r.right()); ++x) {
        if (std::abs(y - g.y(50)) < 2) continue;  // the threshold line itself
        const std::size_t i = (static_cast<std::size_t>(y) * 400 + static_cast<std::size_t>(x)) * 3;
        n += bytes.rgb[i] == 119 && bytes.rgb[i + 1] == 119 && bytes.rgb[i + 2] == 119;
      }
    return n;
  };
  EXPECT_EQ(grey_pixels(g.area()), 0);
  EXPECT_GT(grey_pixels(g.legend()), 0);
}

TEST(PlotImage, RejectsSillySizes) {
  EXPECT_THROW(plot_image(LinePlot{}, 10, 300), std::invalid_argument);
  EXPECT_THROW(plot_image(LinePlot{}, 400, 100000), std::invalid_argument);
}

}  // namespace
}  // namespace viz
