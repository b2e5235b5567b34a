// Line plots: well-formed SVG, finite coordinates, geometry monotone with the
// data, log axes, thresholds and small multiples.
#include <gtest/gtest.h>

#include <algorithm>
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

// The label goes in the legend, where it cannot cover the lines that end
// near the threshold.
TEST(LinePlot, ThresholdLabelIsInTheLegend) {
  LinePlot p;
  p.y_min = 0;
  p.y_max = 100;
  p.series.push_back({"hypercube", {{1, 100}, {64, 78}}});
  p.thresholds.push_back({78, "paper: 78% at 64"});
  const test::XmlCheck doc = test::check_xml(plot_svg(p));
  const detail::PlotGeometry g(p, {0, 0, 520, 340}, 6.6);
  std::size_t labels = 0;
  for (const auto& e : doc.elements) {
    if (e.tag != "text" || e.text != "paper: 78% at 64") continue;
    ++labels;
    EXPECT_GE(std::stod(e.attrs.at("x")), g.legend().left);
    EXPECT_GE(std::stod(e.attrs.at("y")), g.legend().top);
    EXPECT_LE(std::stod(e.attrs.at("y")), g.legend().bottom());
  }
  EXPECT_EQ(labels, 1u);
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

std::size_t utf8_chars(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// Small multiples side by side, as a sweep draws them, with titles that start
// with a long scene name: each title, at a generous estimate of bold
// sans-serif (0.62 em a character), stays inside its own panel, and the
// panel's tooltip keeps the whole title.
TEST(LinePlot, LongTitlesStayInsideTheirPanels) {
  const std::string scene = "a_rather_long_scene_file_name_for_the_class_demo.nff";
  std::vector<LinePlot> panels(3, speedup_plot());
  panels[0].title = scene + ": predicted synthesis time";
  panels[1].title = scene + scene + ": speedup";
  panels[2].title = "short";
  const PlotSize size{};
  const test::XmlCheck doc = test::check_xml(plots_svg(panels, 3, size));
  ASSERT_TRUE(doc.ok) << doc.error;
  std::vector<std::string> tooltips, shown;
  std::size_t panel = 0;
  for (const auto& e : doc.elements) {
    if (e.tag == "title") tooltips.push_back(e.text);
    if (!e.attrs.count("class") || e.attrs.at("class") != "plot-title") continue;
    ASSERT_EQ(e.attrs.at("text-anchor"), "middle");
    const double half = 0.5 * 0.62 * std::stod(e.attrs.at("font-size")) * static_cast<double>(utf8_chars(e.text));
    const double x = std::stod(e.attrs.at("x"));
    EXPECT_GE(x - half, panel * size.width) << e.text;
    EXPECT_LE(x + half, (panel + 1) * size.width) << e.text;
    EXPECT_GE(std::stod(e.attrs.at("font-size")), 11.0);
    shown.push_back(e.text);
    ++panel;
  }
  ASSERT_EQ(panel, 3u);
  // Too long to fit even when shrunk: the start of the scene and what the panel shows remain.
  EXPECT_EQ(shown[1].rfind("a_rather", 0), 0u) << shown[1];
  EXPECT_NE(shown[1].find("\u2026"), std::string::npos) << shown[1];
  EXPECT_EQ(shown[1].substr(shown[1].size() - 9), ": speedup");
  EXPECT_EQ(shown[2], "short");
  for (const LinePlot& p : panels)
    EXPECT_NE(std::find(tooltips.begin(), tooltips.end(), p.title), tooltips.end()) << p.title;
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
