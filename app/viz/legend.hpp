// Colour legends shared by the viz pictures: a colour scale as an SVG
// gradient, and a captioned bar that shows it from 0 to a maximum.
// Invariant: a gradient's id names its scale alone, so the same id may appear
// in several pictures inlined in one page.
#pragma once

#include <string>

#include "app/viz/colour.hpp"
#include "app/viz/svg.hpp"

namespace viz {

// A <linearGradient> of `scale` from 0 to 1 (inside an open <defs>).
void scale_gradient(SvgDocument& doc, const std::string& id, Rgb8 (*scale)(double));

// Caption at (x, y), the gradient `id` below it, 160 wide, labelled 0 and max.
void colour_bar(SvgDocument& doc, double x, double y, const std::string& id, const std::string& caption,
                double max);

}  // namespace viz
