// Line plots as SVG: one panel per plot, drawn in the order grid, thresholds,
// series (clipped to the data area), axes and labels, legend.
#include <algorithm>
#include <cmath>
#include <string>

#include "app/viz/plot.hpp"
#include "app/viz/plot_geometry.hpp"
#include "app/viz/svg.hpp"

namespace viz {
namespace {

using detail::PlotGeometry;
using detail::Rect;

constexpr double char_width = 6.6;  // mean advance of 12px sans-serif

void draw_grid_and_ticks(SvgDocument& doc, const PlotGeometry& g) {
  const Rect& a = g.area();
  doc.open("g", {{"class", "grid"}, {"stroke", "#dddddd"}, {"stroke-width", "1"}});
  for (double v : g.x_ticks().values)
    doc.leaf("line", {{"x1", num(g.x(v))}, {"y1", num(a.top)}, {"x2", num(g.x(v))}, {"y2", num(a.bottom())}});
  for (double v : g.y_ticks().values)
    doc.leaf("line", {{"x1", num(a.left)}, {"y1", num(g.y(v))}, {"x2", num(a.right())}, {"y2", num(g.y(v))}});
  doc.close();
  // The frame goes under the data, so that points on the border stay visible.
  doc.leaf("rect", {{"x", num(a.left)}, {"y", num(a.top)}, {"width", num(a.width)}, {"height", num(a.height)},
                    {"fill", "none"}, {"stroke", "#444444"}});
  doc.open("g", {{"class", "tick-labels"}, {"font-size", "11"}, {"fill", "#333333"}});
  for (std::size_t i = 0; i < g.x_ticks().values.size(); ++i)
    doc.text(g.x_ticks().labels[i], {{"x", num(g.x(g.x_ticks().values[i]))}, {"y", num(a.bottom() + 15)},
                                     {"text-anchor", "middle"}});
  for (std::size_t i = 0; i < g.y_ticks().values.size(); ++i)
    doc.text(g.y_ticks().labels[i], {{"x", num(a.left - 5)}, {"y", num(g.y(g.y_ticks().values[i]) + 4)},
                                     {"text-anchor", "end"}});
  doc.close();
}

void draw_labels(SvgDocument& doc, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  const Rect& p = g.panel();
  if (!plot.title.empty())
    doc.text(plot.title, {{"x", num(a.left + a.width / 2)}, {"y", num(p.top + 20)}, {"text-anchor", "middle"},
                          {"font-size", "14"}, {"font-weight", "bold"}});
  if (!plot.x_label.empty())
    doc.text(plot.x_label, {{"x", num(a.left + a.width / 2)}, {"y", num(a.bottom() + 34)},
                            {"text-anchor", "middle"}, {"font-size", "12"}});
  if (!plot.y_label.empty()) {
    const double cx = p.left + 14, cy = a.top + a.height / 2;
    doc.text(plot.y_label, {{"x", num(cx)}, {"y", num(cy)}, {"text-anchor", "middle"}, {"font-size", "12"},
                            {"transform", "rotate(-90 " + num(cx) + " " + num(cy) + ")"}});
  }
}

std::string points_attr(const std::vector<Point>& pts) {
  std::string s;
  for (const Point& p : pts) s += num(p.x) + "," + num(p.y) + " ";
  if (!s.empty()) s.pop_back();
  return s;
}

void draw_data(SvgDocument& doc, const LinePlot& plot, const PlotGeometry& g, const std::string& clip_id) {
  const Rect& a = g.area();
  doc.open("g", {{"clip-path", "url(#" + clip_id + ")"}});
  for (const Threshold& t : plot.thresholds) {
    if (!g.drawable({g.x_ticks().lo, t.y})) continue;
    doc.leaf("line", {{"class", "threshold"}, {"x1", num(a.left)}, {"y1", num(g.y(t.y))}, {"x2", num(a.right())},
                      {"y2", num(g.y(t.y))}, {"stroke", "#777777"}, {"stroke-dasharray", "2 3"}});
    doc.text(t.label, {{"x", num(a.right() - 4)}, {"y", num(g.y(t.y) - 4)}, {"text-anchor", "end"},
                       {"font-size", "11"}, {"fill", "#555555"}});
  }
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    const std::string colour = detail::series_colour_hex(s, static_cast<int>(i));
    const std::vector<Point> pts = g.pixels(s);
    doc.open("g", {{"class", "series"}, {"stroke", colour}, {"fill", colour}});
    doc.title(s.name);
    doc.leaf("polyline", {{"points", points_attr(pts)}, {"fill", "none"}, {"stroke-width", "2"},
                          {"stroke-dasharray", s.style == LineStyle::dashed ? "6 4" : "none"}});
    if (s.markers)
      for (const Point& p : pts) doc.leaf("circle", {{"cx", num(p.x)}, {"cy", num(p.y)}, {"r", "3"}});
    doc.close();
  }
  doc.close();
}

void draw_legend(SvgDocument& doc, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& l = g.legend();
  if (l.width <= 0) return;
  doc.open("g", {{"class", "legend"}, {"font-size", "12"}});
  double y = l.top + 12;
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    if (s.name.empty()) continue;
    const std::string colour = detail::series_colour_hex(s, static_cast<int>(i));
    doc.leaf("line", {{"x1", num(l.left)}, {"y1", num(y - 4)}, {"x2", num(l.left + 24)}, {"y2", num(y - 4)},
                      {"stroke", colour}, {"stroke-width", "2"},
                      {"stroke-dasharray", s.style == LineStyle::dashed ? "6 4" : "none"}});
    doc.text(s.name, {{"x", num(l.left + 30)}, {"y", num(y)}});
    y += 16;
  }
  doc.close();
}

// Ids are document-wide when SVGs are inlined in one HTML page, so the clip id
// is derived from the rectangle itself: equal ids always mean equal clips.
std::string clip_id_for(const Rect& a) {
  std::string id = "viz-clip-" + num(a.left) + "-" + num(a.top) + "-" + num(a.width) + "-" + num(a.height);
  std::replace(id.begin(), id.end(), '.', '_');
  return id;
}

void draw_panel(SvgDocument& doc, const LinePlot& plot, Rect panel) {
  const PlotGeometry g(plot, panel, char_width);
  const Rect& a = g.area();
  const std::string clip_id = clip_id_for(a);
  doc.open("g", {{"class", "plot"}});
  doc.open("clipPath", {{"id", clip_id}});
  // A little wider than the area so that markers on the border show whole.
  doc.leaf("rect", {{"x", num(a.left - 4)}, {"y", num(a.top - 4)}, {"width", num(a.width + 8)},
                    {"height", num(a.height + 8)}});
  doc.close();
  draw_grid_and_ticks(doc, g);
  draw_data(doc, plot, g, clip_id);
  draw_labels(doc, plot, g);
  draw_legend(doc, plot, g);
  doc.close();
}

}  // namespace

std::string plot_svg(const LinePlot& plot, PlotSize size) {
  return plots_svg({plot}, 1, size);
}

std::string plots_svg(const std::vector<LinePlot>& plots, int columns, PlotSize panel) {
  columns = std::clamp(columns, 1, std::max(1, static_cast<int>(plots.size())));
  const int rows = (static_cast<int>(plots.size()) + columns - 1) / columns;
  SvgDocument doc(panel.width * columns, panel.height * std::max(rows, 1));
  doc.leaf("rect", {{"width", "100%"}, {"height", "100%"}, {"fill", "white"}});
  for (std::size_t i = 0; i < plots.size(); ++i) {
    const int c = static_cast<int>(i) % columns, r = static_cast<int>(i) / columns;
    draw_panel(doc, plots[i], {c * panel.width, r * panel.height, panel.width, panel.height});
  }
  return doc.finish();
}

}  // namespace viz
