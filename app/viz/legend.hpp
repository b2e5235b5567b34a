// Internal to the viz library: the captioned colour bar that the machine
// drawing and the timeline use to show a colour scale from 0 to a maximum.
// Invariant: the bar spans colour_bar_width px, 0 at its left end.
#pragma once

#include <string>

#include "app/viz/colour.hpp"
#include "app/viz/drawing.hpp"

namespace viz::detail {

constexpr double colour_bar_width = 160;

// Caption with its baseline at y, the bar of `scale` below it, labelled 0 and max.
void colour_bar(cairo_t* cr, double x, double y, Rgb8 (*scale)(double), const std::string& caption, double max);

}  // namespace viz::detail
