// Line plots rasterised into a tracer::Image (write it with write_png): the
// same layout as plot_svg (grid, axes, tick values, thresholds, lines,
// markers, legend), with all text in a built-in 5x7 bitmap font that has
// capitals, digits and common punctuation only (lower case is drawn as capitals).
#pragma once

#include "app/viz/plot.hpp"
#include "tracer/image.hpp"

namespace viz {

// Throws std::invalid_argument if width or height is below 64 or above 8192.
tracer::Image plot_image(const LinePlot& plot, int width = 640, int height = 420);

}  // namespace viz
