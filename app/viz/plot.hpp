// Line plots of experiment results (the paper's Table 2 timings, Figure 8's
// efficiency / miss ratio / page communications against cache size), drawn
// once with cairo and written as SVG or PDF here, as PNG by plot_raster.hpp.
// Each panel: grid, frame, thresholds, series clipped to the data area, tick
// values, title (shrunk, then shortened around an ellipsis, to fit its
// panel), axis captions, and a legend that names the series when there are
// several and the labelled thresholds.
// Invariants: points that cannot be drawn (non-finite, or <= 0 on a log
// axis) are skipped, never drawn; series keep the order of their points;
// larger data values map to larger x and to smaller (higher) y pixels.
#pragma once

#include <string>
#include <vector>

#include "app/viz/line_plot.hpp"

namespace viz {

// One plot as a standalone SVG document (ready to inline, see svg.hpp).
std::string plot_svg(const LinePlot& plot, PlotSize size = {});

// Small multiples: the plots in a grid of `columns` panels of `panel` size
// each, in one SVG (e.g. Figure 8's three panels side by side).
std::string plots_svg(const std::vector<LinePlot>& plots, int columns, PlotSize panel = {});

// The same pictures as PDF documents (the bytes of the file), sizes in points.
std::string plot_pdf(const LinePlot& plot, PlotSize size = {});
std::string plots_pdf(const std::vector<LinePlot>& plots, int columns, PlotSize panel = {});

}  // namespace viz
