// Line plots as pictures in a tracer::Image (write it with write_png): the
// drawing of plot.hpp on a cairo image surface, text anti-aliased.
#pragma once

#include "app/viz/line_plot.hpp"
#include "tracer/image.hpp"

namespace viz {

// Throws std::invalid_argument if width or height is below 64 or above 8192.
tracer::Image plot_image(const LinePlot& plot, int width = 640, int height = 420);

}  // namespace viz
