// Rasterised plots: the size asked for, data drawn where the geometry puts it.
#include <gtest/gtest.h>

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

TEST(PlotImage, RejectsSillySizes) {
  EXPECT_THROW(plot_image(LinePlot{}, 10, 300), std::invalid_argument);
  EXPECT_THROW(plot_image(LinePlot{}, 400, 100000), std::invalid_argument);
}

}  // namespace
}  // namespace viz
