// Internal to the viz library: one line plot drawn on a panel of any cairo
// surface (SVG, PDF or image), its parts placed by PlotGeometry; plot.hpp
// and plot_raster.hpp lay panels out and write the documents.
#pragma once

#include <cairo.h>

#include "app/viz/line_plot.hpp"
#include "app/viz/plot_geometry.hpp"

namespace viz::detail {

// Grid, frame, thresholds, the series clipped to the data area, tick values,
// title, axis captions and legend, in that order, within `panel`.
void draw_panel(cairo_t* cr, const LinePlot& plot, Rect panel);

}  // namespace viz::detail
