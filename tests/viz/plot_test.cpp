// Line plots: well-formed SVG, finite coordinates, geometry monotone with the
// data, log axes, thresholds and small multiples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "app/viz/plot.hpp"
#include "app/viz/plot_geometry.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

LinePlot speedup_plot() {
  LinePlot p;
  p.title = "Synthesis time <teapot> & co";
  p.x_label = "processors";
  p.y_label = "seconds";
  p.x_scale = AxisScale::log2;
  p.series.push_back({"measured", {{1, 4000}, {2, 2100}, {4, 1080}, {8, 560}, {16, 300}, {32, 170}, {64, 100}}});
  p.series.push_back({"ideal", {{1, 4000}, {64, 62.5}}, LineStyle::dashed, false, "#888888"});
  return p;
}

std::vector<std::pair<double, double>> polyline_points(const test::XmlElement& e) {
  std::vector<std::pair<double, double>> pts;
  std::istringstream in(e.attrs.at("points"));
  double x = 0, y = 0;
  char comma = 0;
  while (in >> x >> comma >> y) pts.emplace_back(x, y);
  return pts;
}

std::vector<test::XmlElement> polylines(const test::XmlCheck& doc) {
  std::vector<test::XmlElement> out;
  for (const auto& e : doc.elements)
    if (e.tag == "polyline") out.push_back(e);
  return out;
}

bool has_non_finite(const test::XmlCheck& doc) {
  for (const auto& e : doc.elements)
    for (const auto& [k, v] : e.attrs)
      if (v.find("nan") != std::string::npos || v.find("inf") != std::string::npos) return true;
  return false;
}

TEST(LinePlot, SvgIsWellFormedAndFinite) {
  const test::XmlCheck doc = test::check_xml(plot_svg(speedup_plot()));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(doc.elements.front().tag, "svg");
  EXPECT_FALSE(has_non_finite(doc));
}

TEST(LinePlot, EscapesTitle) {
  const std::string svg = plot_svg(speedup_plot());
  EXPECT_NE(svg.find("Synthesis time &lt;teapot&gt; &amp; co"), std::string::npos);
}

TEST(LinePlot, PixelsFollowTheData) {
  // Time falls as processors rise: x pixels increase, y pixels increase (downwards).
  const test::XmlCheck doc = test::check_xml(plot_svg(speedup_plot()));
  const auto lines = polylines(doc);
  ASSERT_EQ(lines.size(), 2u);
  const auto pts = polyline_points(lines[0]);
  ASSERT_EQ(pts.size(), 7u);
  for (std::size_t i = 1; i < pts.size(); ++i) {
    EXPECT_GT(pts[i].first, pts[i - 1].first);
    EXPECT_GT(pts[i].second, pts[i - 1].second);
  }
}

TEST(LinePlot, Log2AxisSpacesDoublingsEvenly) {
  const test::XmlCheck doc = test::check_xml(plot_svg(speedup_plot()));
  const auto pts = polyline_points(polylines(doc)[0]);
  const double step = pts[1].first - pts[0].first;
  for (std::size_t i = 1; i < pts.size(); ++i) EXPECT_NEAR(pts[i].first - pts[i - 1].first, step, 0.02);
}

TEST(LinePlot, SkipsPointsThatCannotBeDrawn) {
  LinePlot p;
  p.x_scale = AxisScale::log2;
  p.series.push_back({"s", {{0, 1}, {1, std::nan("")}, {2, 3}, {std::numeric_limits<double>::infinity(), 1}, {4, 5}}});
  const test::XmlCheck doc = test::check_xml(plot_svg(p));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_FALSE(has_non_finite(doc));
  EXPECT_EQ(polyline_points(polylines(doc)[0]).size(), 2u);
}

TEST(LinePlot, EmptyPlotStillWellFormed) {
  const test::XmlCheck doc = test::check_xml(plot_svg(LinePlot{}));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_FALSE(has_non_finite(doc));
}

TEST(LinePlot, ThresholdDrawnAtItsValue) {
  LinePlot p;
  p.y_min = 0;
  p.y_max = 1;
  p.series.push_back({"efficiency", {{1, 1.0}, {8, 0.2}}});
  p.thresholds.push_back({0.5, "50%"});
  const test::XmlCheck doc = test::check_xml(plot_svg(p));
  ASSERT_EQ(test::count_class(doc, "threshold"), 1u);
  const detail::PlotGeometry g(p, {0, 0, 520, 340}, 6.6);
  for (const auto& e : doc.elements) {
    if (e.attrs.count("class") && e.attrs.at("class") == "threshold") {
      EXPECT_NEAR(std::stod(e.attrs.at("y1")), (g.y(0.0) + g.y(1.0)) / 2, 0.01);
    }
  }
}

TEST(LinePlot, FixedRangeBoundsTheAxis) {
  LinePlot p;
  p.y_min = 0.25;
  p.y_max = 0.75;
  p.series.push_back({"s", {{0, 0.3}, {1, 0.7}}});
  const detail::PlotGeometry g(p, {0, 0, 400, 300}, 6.6);
  EXPECT_DOUBLE_EQ(g.y(0.25), g.area().bottom());
  EXPECT_DOUBLE_EQ(g.y(0.75), g.area().top);
  for (double v : g.y_ticks().values) {
    EXPECT_GE(v, 0.25);
    EXPECT_LE(v, 0.75);
  }
}

TEST(LinePlot, SmallMultiplesHoldEveryPanel) {
  std::vector<LinePlot> panels(3, speedup_plot());
  panels[1].title = "miss ratio";
  panels[2].title = "page communications";
  const test::XmlCheck doc = test::check_xml(plots_svg(panels, 3));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::count_class(doc, "plot"), 3u);
  EXPECT_EQ(std::stod(doc.elements.front().attrs.at("width")), 3 * PlotSize{}.width);
}

TEST(Ticks, LinearTicksAreNiceAndCoverTheRange) {
  const Ticks t = make_ticks(AxisScale::linear, 0.13, 0.87);
  EXPECT_LE(t.lo, 0.13);
  EXPECT_GE(t.hi, 0.87);
  ASSERT_GE(t.values.size(), 3u);
  const double step = t.values[1] - t.values[0];
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step)));
  EXPECT_TRUE(std::fabs(mantissa - 1) < 1e-9 || std::fabs(mantissa - 2) < 1e-9 || std::fabs(mantissa - 5) < 1e-9);
  EXPECT_EQ(t.labels[0], "0.1");
}

TEST(Ticks, Log2TicksArePowersOfTwo) {
  const Ticks t = make_ticks(AxisScale::log2, 1, 64);
  ASSERT_EQ(t.values.size(), 7u);
  EXPECT_EQ(t.labels.back(), "64");
  EXPECT_DOUBLE_EQ(t.values[3], 8.0);
}

TEST(Ticks, DegenerateRangeIsWidened) {
  const Ticks t = make_ticks(AxisScale::linear, 5, 5);
  EXPECT_LT(t.lo, 5);
  EXPECT_GT(t.hi, 5);
}

}  // namespace
}  // namespace viz
