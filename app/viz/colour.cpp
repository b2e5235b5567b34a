// Colour scales and categorical colours; see colour.hpp.
#include "app/viz/colour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace viz {
namespace {

// Piecewise-linear interpolation through evenly spaced control colours.
template <std::size_t N>
Rgb8 interpolate(const std::array<Rgb8, N>& stops, double t) {
  if (!(t > 0.0)) t = 0.0;  // also maps NaN to the low end
  t = std::min(t, 1.0);
  const double pos = t * static_cast<double>(N - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(pos), N - 2);
  const double f = pos - static_cast<double>(i);
  auto mix = [f](std::uint8_t a, std::uint8_t b) {
    return static_cast<std::uint8_t>(std::lround(a + (b - a) * f));
  };
  return {mix(stops[i].r, stops[i + 1].r), mix(stops[i].g, stops[i + 1].g),
          mix(stops[i].b, stops[i + 1].b)};
}

Rgb8 from_hsv(double h, double s, double v) {
  const double c = v * s;
  const double hp = std::fmod(h, 1.0) * 6.0;
  const double x = c * (1.0 - std::fabs(std::fmod(hp, 2.0) - 1.0));
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(hp)) {
    case 0: r = c; g = x; break;
    case 1: r = x; g = c; break;
    case 2: g = c; b = x; break;
    case 3: g = x; b = c; break;
    case 4: r = x; b = c; break;
    default: r = c; b = x; break;
  }
  const double m = v - c;
  auto to8 = [m](double u) { return static_cast<std::uint8_t>(std::lround((u + m) * 255.0)); };
  return {to8(r), to8(g), to8(b)};
}

}  // namespace

std::string hex(Rgb8 c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}

Rgb8 traffic_scale(double t) {
  // Control points sampled from the viridis colour map.
  static constexpr std::array<Rgb8, 6> stops{{{68, 1, 84}, {65, 68, 135}, {42, 120, 142},
                                              {34, 168, 132}, {122, 209, 81}, {253, 231, 37}}};
  return interpolate(stops, t);
}

Rgb8 work_scale(double t) {
  static constexpr std::array<Rgb8, 5> stops{
      {{255, 255, 204}, {254, 217, 118}, {253, 141, 60}, {227, 26, 28}, {128, 0, 38}}};
  return interpolate(stops, t);
}

Rgb8 node_colour(int node) {
  constexpr double golden = 0.6180339887498949;
  const unsigned n = static_cast<unsigned>(node);
  const double hue = std::fmod(0.1 + golden * n, 1.0);
  static constexpr std::array<double, 3> value{0.95, 0.75, 0.55};
  static constexpr std::array<double, 3> saturation{0.65, 0.85, 0.75};
  return from_hsv(hue, saturation[(n / 3) % 3], value[n % 3]);
}

Rgb8 series_colour(int index) {
  static constexpr std::array<Rgb8, 8> palette{{{31, 119, 180}, {214, 39, 40}, {44, 160, 44},
                                                {255, 127, 14}, {148, 103, 189}, {140, 86, 75},
                                                {227, 119, 194}, {23, 190, 207}}};
  return palette[static_cast<unsigned>(index) % palette.size()];
}

}  // namespace viz
