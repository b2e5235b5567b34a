// Line plots: well-formed SVG with unique ids, valid PDF, geometry monotone
// with the data, log axes, thresholds, small multiples, titles that fit.
#include "app/viz/plot.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/viz/plot_geometry.hpp"
#include "app/viz/text.hpp"
#include "picture_check.hpp"
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

TEST(LinePlot, SvgIsWellFormedAndFinite) {
  const std::string svg = plot_svg(speedup_plot());
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 40);  // no XML declaration: ready to inline
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(doc.elements.front().tag, "svg");
  EXPECT_EQ(test::first_non_finite_attribute(doc), "");
}

// Text is drawn: more glyphs with a title than without, each referring
// only to glyphs defined in the same document.
TEST(LinePlot, SvgTextIsGlyphsDefinedInTheDocument) {
  LinePlot p = speedup_plot();
  const std::string titled = plot_svg(p);
  p.title.clear();
  const std::string untitled = plot_svg(p);
  const auto uses = [](const std::string& svg) {
    std::size_t n = 0;
    for (std::size_t at = svg.find("<use"); at != std::string::npos; at = svg.find("<use", at + 1)) ++n;
    return n;
  };
  EXPECT_GT(uses(titled), uses(untitled) + 10);
  const std::set<std::string> ids = test::svg_ids(titled);
  for (const std::string& r : test::svg_references(titled)) EXPECT_EQ(ids.count(r), 1u) << r;
}

TEST(LinePlot, IdsAreUniqueAcrossDocumentsAndResolve) {
  LinePlot clipped = speedup_plot();
  clipped.y_max = 1000;  // the data goes beyond the area, so its clip is in the document
  const std::string a = plot_svg(clipped), b = plot_svg(clipped);
  const std::set<std::string> ids_a = test::svg_ids(a), ids_b = test::svg_ids(b);
  ASSERT_FALSE(ids_a.empty());
  for (const std::string& id : ids_a) EXPECT_EQ(ids_b.count(id), 0u) << id;
  for (const std::string& r : test::svg_references(a)) EXPECT_EQ(ids_a.count(r), 1u) << r;
  for (const std::string& r : test::svg_references(b)) EXPECT_EQ(ids_b.count(r), 1u) << r;
  EXPECT_FALSE(test::svg_references(a).empty());
}

TEST(LinePlot, PdfIsAPdf) {
  EXPECT_TRUE(test::is_pdf(plot_pdf(speedup_plot())));
  EXPECT_TRUE(test::is_pdf(plots_pdf({speedup_plot(), LinePlot{}}, 2)));
}

TEST(LinePlot, PixelsFollowTheData) {
  // Time falls as processors rise: x pixels increase, y pixels increase (downwards).
  const LinePlot p = speedup_plot();
  const detail::PlotGeometry g(p, {0, 0, 520, 340});
  const std::vector<Point> pts = g.pixels(p.series[0]);
  ASSERT_EQ(pts.size(), 7u);
  for (std::size_t i = 1; i < pts.size(); ++i) {
    EXPECT_GT(pts[i].x, pts[i - 1].x);
    EXPECT_GT(pts[i].y, pts[i - 1].y);
  }
  for (const Point& q : pts) {
    EXPECT_TRUE(q.x >= g.area().left && q.x <= g.area().right()) << q.x;
    EXPECT_TRUE(q.y >= g.area().top && q.y <= g.area().bottom()) << q.y;
  }
}

TEST(LinePlot, Log2AxisSpacesDoublingsEvenly) {
  const LinePlot p = speedup_plot();
  const std::vector<Point> pts = detail::PlotGeometry(p, {0, 0, 520, 340}).pixels(p.series[0]);
  const double step = pts[1].x - pts[0].x;
  for (std::size_t i = 1; i < pts.size(); ++i) EXPECT_NEAR(pts[i].x - pts[i - 1].x, step, 1e-9);
}

TEST(LinePlot, SkipsPointsThatCannotBeDrawn) {
  LinePlot p;
  p.x_scale = AxisScale::log2;
  p.series.push_back({"s", {{0, 1}, {1, std::nan("")}, {2, 3}, {std::numeric_limits<double>::infinity(), 1}, {4, 5}}});
  EXPECT_EQ(detail::PlotGeometry(p, {0, 0, 520, 340}).pixels(p.series[0]).size(), 2u);
  const test::XmlCheck doc = test::check_xml(plot_svg(p));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::first_non_finite_attribute(doc), "");
}

TEST(LinePlot, EmptyPlotStillWellFormed) {
  const test::XmlCheck doc = test::check_xml(plot_svg(LinePlot{}));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::first_non_finite_attribute(doc), "");
}

// Text that is not UTF-8 is drawn with '?' for its bad bytes, not refused.
TEST(LinePlot, InvalidUtf8IsReplaced) {
  EXPECT_EQ(detail::valid_utf8("a\xff"
                               "b\xc3\xa9\xe2\x82"),
            "a?b\xc3\xa9??");
  LinePlot p = speedup_plot();
  p.title = "bad \xc0\xaf title";
  EXPECT_TRUE(test::check_xml(plot_svg(p)).ok);
}

TEST(LinePlot, ThresholdLabelIsInTheLegend) {
  LinePlot p;
  p.y_min = 0;
  p.y_max = 100;
  p.series.push_back({"hypercube", {{1, 100}, {64, 78}}});
  p.thresholds.push_back({78, "paper: 78% at 64"});
  const detail::PlotGeometry g(p, {0, 0, 520, 340});
  EXPECT_GE(g.legend().left, g.area().right());
  EXPECT_GE(g.legend().width, detail::text_width("paper: 78% at 64", {detail::legend_font}));
  EXPECT_NEAR(g.y(78), g.area().bottom() - 0.78 * g.area().height, 1e-9);
  p.thresholds.push_back({-1, "off the axis"});
  p.y_scale = AxisScale::log10;
  EXPECT_FALSE(detail::PlotGeometry(p, {0, 0, 520, 340}).drawable(p.thresholds[1]));
}

TEST(LinePlot, FixedRangeBoundsTheAxis) {
  LinePlot p;
  p.y_min = 0.25;
  p.y_max = 0.75;
  p.series.push_back({"s", {{0, 0.3}, {1, 0.7}}});
  const detail::PlotGeometry g(p, {0, 0, 400, 300});
  EXPECT_DOUBLE_EQ(g.y(0.25), g.area().bottom());
  EXPECT_DOUBLE_EQ(g.y(0.75), g.area().top);
  for (double v : g.y_ticks().values) {
    EXPECT_GE(v, 0.25);
    EXPECT_LE(v, 0.75);
  }
}

TEST(LinePlot, SmallMultiplesHoldEveryPanel) {
  std::vector<LinePlot> panels(3, speedup_plot());
  const test::XmlCheck doc = test::check_xml(plots_svg(panels, 3));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(std::stod(doc.elements.front().attrs.at("width")), 3 * PlotSize{}.width);
  EXPECT_EQ(std::stod(doc.elements.front().attrs.at("height")), PlotSize{}.height);
  const test::XmlCheck column = test::check_xml(plots_svg(panels, 1));
  EXPECT_EQ(std::stod(column.elements.front().attrs.at("height")), 3 * PlotSize{}.height);
}

// Titles as long as a sweep's with a long scene name: shrunk to fit, and
// when that is not enough, their middle gives way to an ellipsis.
TEST(LinePlot, LongTitlesFitTheirPanels) {
  const std::string scene = "a_rather_long_scene_file_name_for_the_class_demo.nff";
  const double room = PlotSize{}.width - 8;
  const detail::Font title{detail::title_font_max, true};
  const auto [shrunk, shrunk_font] =
      detail::fit_text(scene + ": predicted synthesis time", title, detail::title_font_min, room);
  EXPECT_LE(detail::text_width(shrunk, shrunk_font), room);
  EXPECT_GE(shrunk_font.size, detail::title_font_min);
  const auto [cut, cut_font] = detail::fit_text(scene + scene + ": speedup", title, detail::title_font_min, room);
  EXPECT_LE(detail::text_width(cut, cut_font), room);
  EXPECT_EQ(cut_font.size, detail::title_font_min);
  EXPECT_EQ(cut.rfind("a_rather", 0), 0u) << cut;
  EXPECT_NE(cut.find("\u2026"), std::string::npos) << cut;
  EXPECT_EQ(cut.substr(cut.size() - 9), ": speedup");
  const auto [kept, kept_font] = detail::fit_text("short", title, detail::title_font_min, room);
  EXPECT_EQ(kept, "short");
  EXPECT_EQ(kept_font.size, detail::title_font_max);
}

TEST(Text, WidthGrowsWithTextAndSize) {
  const double a = detail::text_width("processors", {12});
  EXPECT_GT(a, 30);
  EXPECT_LT(a, 120);
  EXPECT_NEAR(detail::text_width("processors", {24}), 2 * a, 0.01 * a);
  EXPECT_GT(detail::text_width("processors", {12, true}), a);
  EXPECT_EQ(detail::text_width("", {12}), 0);
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
