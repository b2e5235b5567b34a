// Internal to the viz library: where a plot's parts go on a panel, shared by
// the SVG writer and the rasteriser so both draw the same picture.
// Invariants: the plot area has positive size; x() and y() are finite for any
// drawable value and increasing / decreasing respectively.
#pragma once

#include <string>
#include <vector>

#include "app/viz/plot.hpp"

namespace viz::detail {

struct Rect {
  double left = 0, top = 0, width = 0, height = 0;
  double right() const { return left + width; }
  double bottom() const { return top + height; }
};

class PlotGeometry {
 public:
  // `panel` is the whole panel; `char_width` is the mean advance of the font
  // used for text (sizes the legend and the tick label gutter).
  PlotGeometry(const LinePlot& plot, Rect panel, double char_width);

  const Rect& panel() const { return panel_; }
  const Rect& area() const { return area_; }      // the data area
  const Rect& legend() const { return legend_; }  // empty width: no legend
  const Ticks& x_ticks() const { return x_ticks_; }
  const Ticks& y_ticks() const { return y_ticks_; }

  double x(double data_x) const;
  double y(double data_y) const;
  // A series' points that can be drawn, in pixels, in their original order.
  std::vector<Point> pixels(const Series& s) const;
  bool drawable(const Point& p) const;

 private:
  const LinePlot& plot_;
  Rect panel_, area_, legend_;
  Ticks x_ticks_, y_ticks_;
};

// The series colour as "#rrggbb".
std::string series_colour_hex(const Series& s, int index);

}  // namespace viz::detail
