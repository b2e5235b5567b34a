// Line plots as SVG: one panel per plot, drawn in the order grid, thresholds,
// series (clipped to the data area), axes and labels, legend (series, then
// thresholds).
// A title always fits its panel: its font shrinks down to a floor and, if
// still too wide, its middle gives way to an ellipsis; the whole title stays
// in the panel's <title>.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "app/viz/plot.hpp"
#include "app/viz/plot_geometry.hpp"
#include "app/viz/svg.hpp"

namespace viz {
namespace {

using detail::PlotGeometry;
using detail::Rect;

constexpr double char_width = 6.6;  // mean advance of 12px sans-serif
// Mean advance of bold sans-serif per px of font size, a little generous
// (DejaVu Sans Bold measures about 0.58 on plot titles).
constexpr double bold_em = 0.62;
constexpr double title_font_max = 14, title_font_min = 11;
constexpr double title_pad = 4;  // between a title and its panel's sides
constexpr const char* threshold_grey = "#777777";
constexpr const char* threshold_dashes = "2 3";

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

// Byte offsets where the UTF-8 characters of `s` start, and s.size() last.
std::vector<std::size_t> char_starts(const std::string& s) {
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < s.size(); ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) starts.push_back(i);
  starts.push_back(s.size());
  return starts;
}

struct FittedTitle {
  std::string text;
  double font_size = 0;
  double width = 0;  // estimated
};

// The title at the largest font size that fits `room`, no smaller than the
// floor; too long even then, it keeps its beginning and end around an ellipsis.
FittedTitle fit_title(const std::string& title, double room) {
  const std::vector<std::size_t> starts = char_starts(title);
  const auto chars = static_cast<double>(starts.size() - 1);
  const double size = std::clamp(room / (bold_em * chars), title_font_min, title_font_max);
  if (chars * bold_em * size <= room) return {title, size, chars * bold_em * size};
  const auto fit = static_cast<std::size_t>(std::max(0.0, std::floor(room / (bold_em * size)) - 1));
  const std::size_t tail = fit / 2, head = fit - tail;
  const std::string text = title.substr(0, starts[head]) + "\u2026" + title.substr(starts[starts.size() - 1 - tail]);
  return {text, size, static_cast<double>(fit + 1) * bold_em * size};
}

void draw_labels(SvgDocument& doc, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  const Rect& p = g.panel();
  if (!plot.title.empty()) {
    const FittedTitle t = fit_title(plot.title, p.width - 2 * title_pad);
    // Centred over the data area, unless that would push it off the panel.
    const double x = std::clamp(a.left + a.width / 2, p.left + title_pad + t.width / 2,
                                std::max(p.left + title_pad + t.width / 2, p.right() - title_pad - t.width / 2));
    doc.text(t.text, {{"class", "plot-title"}, {"x", num(x)}, {"y", num(p.top + 20)}, {"text-anchor", "middle"},
                      {"font-size", num(t.font_size)}, {"font-weight", "bold"}});
  }
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
                      {"y2", num(g.y(t.y))}, {"stroke", threshold_grey}, {"stroke-dasharray", threshold_dashes}});
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
  for (const Threshold& t : plot.thresholds) {
    if (t.label.empty() || !g.drawable({g.x_ticks().lo, t.y})) continue;
    doc.leaf("line", {{"x1", num(l.left)}, {"y1", num(y - 4)}, {"x2", num(l.left + 24)}, {"y2", num(y - 4)},
                      {"stroke", threshold_grey}, {"stroke-dasharray", threshold_dashes}});
    doc.text(t.label, {{"x", num(l.left + 30)}, {"y", num(y)}, {"fill", "#555555"}});
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
  if (!plot.title.empty()) doc.title(plot.title);
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
