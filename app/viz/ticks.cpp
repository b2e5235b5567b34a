// Nice tick values: steps of 1, 2 or 5 times a power of ten on linear axes,
// powers of the base (thinned when there are too many) on log axes.
#include "app/viz/ticks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace viz {
namespace {

double nice_step(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double nice = norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0;
  return nice * mag;
}

Ticks linear_ticks(double lo, double hi, int target) {
  if (hi - lo <= 0.0) {
    const double pad = lo == 0.0 ? 1.0 : std::fabs(lo) * 0.1;
    lo -= pad;
    hi += pad;
  }
  const double step = nice_step((hi - lo) / std::max(target, 2));
  Ticks t;
  const long first = std::lround(std::floor(lo / step + 1e-9));
  const long last = std::lround(std::ceil(hi / step - 1e-9));
  t.lo = static_cast<double>(first) * step;
  t.hi = static_cast<double>(last) * step;
  for (long k = first; k <= last; ++k) {
    // Snap to zero so "-0" or 1e-17 never shows up as a label.
    const double v = std::fabs(static_cast<double>(k) * step) < step * 1e-9 ? 0.0 : static_cast<double>(k) * step;
    t.values.push_back(v);
    t.labels.push_back(format_number(v));
  }
  return t;
}

Ticks log_ticks(double base, double lo, double hi) {
  const double lb = std::log(base);
  long kmin = std::lround(std::floor(std::log(lo) / lb + 1e-9));
  long kmax = std::lround(std::ceil(std::log(hi) / lb - 1e-9));
  if (kmax <= kmin) kmax = kmin + 1;
  const long stride = std::max(1L, (kmax - kmin + 9) / 10);
  Ticks t;
  t.lo = std::pow(base, static_cast<double>(kmin));
  t.hi = std::pow(base, static_cast<double>(kmax));
  for (long k = kmin; k <= kmax; k += stride) {
    const double v = std::pow(base, static_cast<double>(k));
    t.values.push_back(v);
    t.labels.push_back(format_number(v));
  }
  return t;
}

}  // namespace

Ticks make_ticks(AxisScale scale, double lo, double hi, int target_count) {
  if (lo > hi) std::swap(lo, hi);
  switch (scale) {
    case AxisScale::log2: return log_ticks(2.0, lo, hi);
    case AxisScale::log10: return log_ticks(10.0, lo, hi);
    case AxisScale::linear: break;
  }
  return linear_ticks(lo, hi, target_count);
}

double axis_coordinate(AxisScale scale, double value) {
  switch (scale) {
    case AxisScale::log2: return std::log2(value);
    case AxisScale::log10: return std::log10(value);
    case AxisScale::linear: break;
  }
  return value;
}

std::string format_number(double value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.7g", value);
  const double mag = std::fabs(value);
  if (mag != 0.0 && (mag < 1e-4 || mag >= 1e7)) std::snprintf(buf, sizeof buf, "%.3g", value);
  return buf;
}

}  // namespace viz
