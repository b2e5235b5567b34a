// Axis scales and "nice" tick values for plots.
// Invariants: make_ticks returns lo < hi, finite, covering the requested
// range, with 2..~12 tick values in increasing order inside [lo, hi]; on log
// scales lo and hi are positive powers of the base.
#pragma once

#include <string>
#include <vector>

namespace viz {

enum class AxisScale { linear, log2, log10 };

struct Ticks {
  double lo = 0, hi = 1;            // the axis range after rounding outwards
  std::vector<double> values;       // tick positions, in data units
  std::vector<std::string> labels;  // one per value
};

// Ticks covering [lo, hi] (data units); on a log scale both must be > 0.
// A degenerate range (lo == hi) is widened around the value.
Ticks make_ticks(AxisScale scale, double lo, double hi, int target_count = 6);

// The value along the axis before the affine map to pixels: v or log(v).
double axis_coordinate(AxisScale scale, double value);

// Compact label: up to 6 significant digits, no exponent for ordinary magnitudes.
std::string format_number(double value);

}  // namespace viz
