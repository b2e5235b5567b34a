// Colours for the viz library: 8-bit sRGB values, continuous colour scales
// for quantities (traffic, work) and a stable categorical colour per node.
// Invariants: scale functions clamp their argument to [0, 1]; node_colour(i)
// depends only on i, so a node keeps its colour across pictures and runs.
#pragma once

#include <cstdint>
#include <string>

namespace viz {

struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
  constexpr bool operator==(const Rgb8&) const = default;
};

// "#rrggbb", for SVG and HTML.
std::string hex(Rgb8 c);

// Perceptually ordered dark-blue -> green -> yellow scale (for link traffic).
Rgb8 traffic_scale(double t);
// Pale yellow -> orange -> dark red scale (for work per node).
Rgb8 work_scale(double t);

// Categorical colour of node i: hues stepped by the golden ratio so that
// neighbouring ids differ strongly, with three lightness bands to separate
// hues that come close once there are many nodes.
Rgb8 node_colour(int node);

// Colour of the i-th series of a plot (a fixed qualitative palette, cycled).
Rgb8 series_colour(int index);

}  // namespace viz
