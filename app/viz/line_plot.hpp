// The plain data of a line plot (plot.hpp draws it): series of points, the
// reference lines, the axes' scales and ends, and a panel's size.
// Invariants (kept by the drawing, not by these types): points that cannot
// be drawn (non-finite, or <= 0 on a log axis) are skipped; series keep the
// order of their points.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "app/viz/ticks.hpp"

namespace viz {

struct Point {
  double x = 0, y = 0;
};

enum class LineStyle { solid, dashed };

struct Series {
  std::string name{};           // legend entry; empty: not listed
  std::vector<Point> points{};  // drawn in this order
  LineStyle style = LineStyle::solid;  // dashed for reference lines ("ideal")
  bool markers = true;        // a dot on every point
  std::string colour{};         // "#rrggbb"; empty: the palette colour of its index
};

// A horizontal reference line across the plot (the paper's 50% efficiency),
// named in the legend rather than over the data.
struct Threshold {
  double y = 0;
  std::string label{};  // legend entry; empty: not listed
};

struct LinePlot {
  std::string title{};
  std::string x_label{};
  std::string y_label{};
  AxisScale x_scale = AxisScale::linear;
  AxisScale y_scale = AxisScale::linear;
  std::optional<double> y_min{};  // fixed axis ends; otherwise from the data
  std::optional<double> y_max{};
  bool y_from_zero = true;      // on a linear y axis, include 0 unless y_min is set
  std::vector<Series> series{};
  std::vector<Threshold> thresholds{};
};

struct PlotSize {
  double width = 520;
  double height = 340;
};

}  // namespace viz
