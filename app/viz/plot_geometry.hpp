// Internal to the viz library: where a plot's parts go on a panel, measured
// in the pictures' font (text.hpp), so every surface draws the same picture.
// Invariants: the plot area has positive size; x() and y() are finite for any
// drawable value and increasing / decreasing respectively; the legend lists
// the series only when there are several named ones, and labelled thresholds
// always; without entries it has zero width.
#pragma once

#include <string>
#include <vector>

#include "app/viz/line_plot.hpp"

namespace viz::detail {

struct Rect {
  double left = 0, top = 0, width = 0, height = 0;
  double right() const { return left + width; }
  double bottom() const { return top + height; }
};

// Fonts of a plot's text, in px.
constexpr double tick_font = 11, label_font = 12, legend_font = 12;
constexpr double title_font_max = 14, title_font_min = 11;
constexpr double legend_step = 16;  // between legend entries

class PlotGeometry {
 public:
  PlotGeometry(const LinePlot& plot, Rect panel);

  const Rect& panel() const { return panel_; }
  const Rect& area() const { return area_; }      // the data area
  const Rect& legend() const { return legend_; }  // zero width: no legend
  bool legend_lists_series() const { return legend_lists_series_; }
  const Ticks& x_ticks() const { return x_ticks_; }
  const Ticks& y_ticks() const { return y_ticks_; }

  double x(double data_x) const;
  double y(double data_y) const;
  // A series' points that can be drawn, in pixels, in their original order.
  std::vector<Point> pixels(const Series& s) const;
  bool drawable(const Point& p) const;
  // A threshold's line can be drawn (and so is listed if labelled).
  bool drawable(const Threshold& t) const;

 private:
  const LinePlot& plot_;
  Rect panel_, area_, legend_;
  bool legend_lists_series_ = false;
  Ticks x_ticks_, y_ticks_;
};

}  // namespace viz::detail
