// Line plots as images; see plot_raster.hpp.
#include "app/viz/plot_raster.hpp"

#include <stdexcept>
#include <string>

#include "app/viz/drawing.hpp"
#include "app/viz/plot_panel.hpp"

namespace viz {

tracer::Image plot_image(const LinePlot& plot, int width, int height) {
  if (width < 64 || height < 64 || width > 8192 || height > 8192)
    throw std::invalid_argument("plot image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " not within 64..8192");
  const detail::Rect panel{0, 0, static_cast<double>(width), static_cast<double>(height)};
  return detail::draw_image("plot image", width, height, [&](cairo_t* cr) { detail::draw_panel(cr, plot, panel); });
}

}  // namespace viz
