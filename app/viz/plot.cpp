// Line plots laid out in a grid of panels and written as SVG or PDF; see
// plot.hpp.
#include "app/viz/plot.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "app/viz/drawing.hpp"
#include "app/viz/plot_panel.hpp"

namespace viz {
namespace {

using detail::draw_panel;

struct Grid {
  int columns = 1, rows = 1;
  double width = 0, height = 0;
};

Grid grid_of(const std::vector<LinePlot>& plots, int columns, PlotSize panel) {
  Grid g;
  g.columns = std::clamp(columns, 1, std::max(1, static_cast<int>(plots.size())));
  g.rows = std::max(1, (static_cast<int>(plots.size()) + g.columns - 1) / g.columns);
  g.width = panel.width * g.columns;
  g.height = panel.height * g.rows;
  return g;
}

detail::Draw draw_panels(const std::vector<LinePlot>& plots, const Grid& grid, PlotSize panel) {
  return [&plots, grid, panel](cairo_t* cr) {
    for (std::size_t i = 0; i < plots.size(); ++i) {
      const int c = static_cast<int>(i) % grid.columns, r = static_cast<int>(i) / grid.columns;
      draw_panel(cr, plots[i], {c * panel.width, r * panel.height, panel.width, panel.height});
    }
  };
}

}  // namespace

std::string plot_svg(const LinePlot& plot, PlotSize size) { return plots_svg({plot}, 1, size); }

std::string plots_svg(const std::vector<LinePlot>& plots, int columns, PlotSize panel) {
  const Grid g = grid_of(plots, columns, panel);
  return detail::draw_svg("plot SVG", g.width, g.height, draw_panels(plots, g, panel));
}

std::string plot_pdf(const LinePlot& plot, PlotSize size) { return plots_pdf({plot}, 1, size); }

std::string plots_pdf(const std::vector<LinePlot>& plots, int columns, PlotSize panel) {
  const Grid g = grid_of(plots, columns, panel);
  return detail::draw_pdf("plot PDF", g.width, g.height, draw_panels(plots, g, panel));
}

}  // namespace viz
