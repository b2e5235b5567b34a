// Plot layout: data ranges, ticks and the panel's areas; see plot_geometry.hpp.
#include "app/viz/plot_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/viz/text.hpp"

namespace viz::detail {
namespace {

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) { lo = std::min(lo, v); hi = std::max(hi, v); }
  bool empty() const { return lo > hi; }
};

bool usable(AxisScale scale, double v) {
  return std::isfinite(v) && (scale == AxisScale::linear || v > 0.0);
}

Ticks y_axis(const LinePlot& plot, Range r) {
  for (const Threshold& t : plot.thresholds)
    if (usable(plot.y_scale, t.y)) r.add(t.y);
  if (plot.y_min && usable(plot.y_scale, *plot.y_min)) r.add(*plot.y_min);
  if (plot.y_max && usable(plot.y_scale, *plot.y_max)) r.add(*plot.y_max);
  if (r.empty()) r = plot.y_scale == AxisScale::linear ? Range{0, 1} : Range{1, 10};
  if (plot.y_scale == AxisScale::linear && plot.y_from_zero && !plot.y_min) r.add(0.0);
  Ticks t = make_ticks(plot.y_scale, r.lo, r.hi);
  // A fixed end replaces the rounded one; ticks beyond it are dropped.
  if (plot.y_min && usable(plot.y_scale, *plot.y_min)) t.lo = *plot.y_min;
  if (plot.y_max && usable(plot.y_scale, *plot.y_max) && *plot.y_max > t.lo) t.hi = *plot.y_max;
  if (!(t.hi > t.lo)) t.hi = plot.y_scale == AxisScale::linear ? t.lo + 1.0 : t.lo * 10.0;
  Ticks kept{t.lo, t.hi, {}, {}};
  for (std::size_t i = 0; i < t.values.size(); ++i) {
    if (t.values[i] < t.lo - 1e-12 * std::fabs(t.lo) || t.values[i] > t.hi * (1 + 1e-12)) continue;
    kept.values.push_back(t.values[i]);
    kept.labels.push_back(t.labels[i]);
  }
  return kept;
}

double widest(const std::vector<std::string>& texts, double font_size) {
  double w = 0;
  for (const std::string& s : texts) w = std::max(w, text_width(s, {font_size}));
  return w;
}

}  // namespace

PlotGeometry::PlotGeometry(const LinePlot& plot, Rect panel) : plot_(plot), panel_(panel) {
  Range xr, yr;
  for (const Series& s : plot.series)
    for (const Point& p : s.points)
      if (drawable(p)) {
        xr.add(p.x);
        yr.add(p.y);
      }
  if (xr.empty()) xr = plot.x_scale == AxisScale::linear ? Range{0, 1} : Range{1, 2};
  x_ticks_ = make_ticks(plot.x_scale, xr.lo, xr.hi);
  y_ticks_ = y_axis(plot, yr);

  std::vector<std::string> names;
  for (const Series& s : plot.series)
    if (!s.name.empty()) names.push_back(s.name);
  legend_lists_series_ = names.size() >= 2;
  if (!legend_lists_series_) names.clear();
  for (const Threshold& t : plot.thresholds)
    if (!t.label.empty() && drawable(t)) names.push_back(t.label);
  const double legend_w = names.empty() ? 0.0 : std::min(panel.width * 0.4, 34.0 + widest(names, legend_font));
  const double top = plot.title.empty() ? 12.0 : 32.0;
  const double bottom = plot.x_label.empty() ? 28.0 : 46.0;
  const double left = 14.0 + widest(y_ticks_.labels, tick_font) + (plot.y_label.empty() ? 0.0 : 20.0);
  const double right = legend_w > 0 ? legend_w + 12.0 : 16.0;
  area_ = {panel.left + left, panel.top + top, std::max(10.0, panel.width - left - right),
           std::max(10.0, panel.height - top - bottom)};
  legend_ = {area_.right() + 8.0, area_.top, legend_w,
             names.empty() ? 0.0 : legend_step * static_cast<double>(names.size()) + 8.0};
}

bool PlotGeometry::drawable(const Point& p) const {
  return usable(plot_.x_scale, p.x) && usable(plot_.y_scale, p.y);
}

bool PlotGeometry::drawable(const Threshold& t) const { return usable(plot_.y_scale, t.y); }

double PlotGeometry::x(double data_x) const {
  const double a = axis_coordinate(plot_.x_scale, x_ticks_.lo);
  const double b = axis_coordinate(plot_.x_scale, x_ticks_.hi);
  return area_.left + (axis_coordinate(plot_.x_scale, data_x) - a) / (b - a) * area_.width;
}

double PlotGeometry::y(double data_y) const {
  const double a = axis_coordinate(plot_.y_scale, y_ticks_.lo);
  const double b = axis_coordinate(plot_.y_scale, y_ticks_.hi);
  return area_.bottom() - (axis_coordinate(plot_.y_scale, data_y) - a) / (b - a) * area_.height;
}

std::vector<Point> PlotGeometry::pixels(const Series& s) const {
  std::vector<Point> out;
  for (const Point& p : s.points)
    if (drawable(p)) out.push_back({x(p.x), y(p.y)});
  return out;
}

}  // namespace viz::detail
