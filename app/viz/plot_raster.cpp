// Rasterised line plots: PlotGeometry places everything as for SVG, Canvas draws.
#include "app/viz/plot_raster.hpp"

#include <stdexcept>
#include <string>

#include "app/viz/canvas.hpp"
#include "app/viz/plot_geometry.hpp"

namespace viz {
namespace {

using detail::Align;
using detail::Canvas;
using detail::PlotGeometry;
using detail::Rect;

constexpr Rgb8 ink{51, 51, 51};
constexpr Rgb8 grid_grey{221, 221, 221};
constexpr Rgb8 threshold_grey{119, 119, 119};

Rgb8 parse_hex(const std::string& s, Rgb8 fallback) {
  if (s.size() != 7 || s[0] != '#') return fallback;
  try {
    const unsigned long v = std::stoul(s.substr(1), nullptr, 16);
    return {static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)};
  } catch (const std::exception&) {
    return fallback;
  }
}

Rgb8 colour_of(const Series& s, int index) { return parse_hex(s.colour, series_colour(index)); }

void draw_axes(Canvas& c, const PlotGeometry& g) {
  const Rect& a = g.area();
  for (std::size_t i = 0; i < g.x_ticks().values.size(); ++i) {
    const double x = g.x(g.x_ticks().values[i]);
    c.line({x, a.top}, {x, a.bottom()}, 1, grid_grey);
    c.text(x, a.bottom() + 6, g.x_ticks().labels[i], 1, ink, Align::centre);
  }
  for (std::size_t i = 0; i < g.y_ticks().values.size(); ++i) {
    const double y = g.y(g.y_ticks().values[i]);
    c.line({a.left, y}, {a.right(), y}, 1, grid_grey);
    c.text(a.left - 6, y - 3, g.y_ticks().labels[i], 1, ink, Align::right);
  }
  // The frame goes under the data, so that points on the border stay visible.
  c.line({a.left, a.top}, {a.right(), a.top}, 1, ink);
  c.line({a.left, a.bottom()}, {a.right(), a.bottom()}, 1, ink);
  c.line({a.left, a.top}, {a.left, a.bottom()}, 1, ink);
  c.line({a.right(), a.top}, {a.right(), a.bottom()}, 1, ink);
}

void draw_data(Canvas& c, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  c.set_clip({a.left - 4, a.top - 4, a.width + 8, a.height + 8});
  for (const Threshold& t : plot.thresholds) {
    if (!g.drawable({g.x_ticks().lo, t.y})) continue;
    c.line({a.left, g.y(t.y)}, {a.right(), g.y(t.y)}, 1, threshold_grey, 3);
  }
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    const Rgb8 colour = colour_of(s, static_cast<int>(i));
    const std::vector<Point> pts = g.pixels(s);
    for (std::size_t k = 1; k < pts.size(); ++k)
      c.line(pts[k - 1], pts[k], 2, colour, s.style == LineStyle::dashed ? 5 : 0);
    if (s.markers)
      for (const Point& p : pts) c.disk(p, 3, colour);
  }
  c.reset_clip();
}

void draw_labels(Canvas& c, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  const Rect& p = g.panel();
  const int title_scale = Canvas::text_width(plot.title, 2) <= p.width - 8 ? 2 : 1;
  c.text(a.left + a.width / 2, p.top + 8, plot.title, title_scale, {0, 0, 0}, Align::centre);
  c.text(a.left + a.width / 2, a.bottom() + 26, plot.x_label, 1, ink, Align::centre);
  c.text_vertical(p.left + 12, a.top + a.height / 2, plot.y_label, 1, ink);
}

void draw_legend(Canvas& c, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& l = g.legend();
  if (l.width <= 0) return;
  double y = l.top + 8;
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    if (s.name.empty()) continue;
    const Rgb8 colour = colour_of(s, static_cast<int>(i));
    c.line({l.left, y}, {l.left + 24, y}, 2, colour, s.style == LineStyle::dashed ? 5 : 0);
    c.text(l.left + 30, y - 3, s.name, 1, ink);
    y += 16;
  }
  for (const Threshold& t : plot.thresholds) {
    if (t.label.empty() || !g.drawable({g.x_ticks().lo, t.y})) continue;
    c.line({l.left, y}, {l.left + 24, y}, 1, threshold_grey, 3);
    c.text(l.left + 30, y - 3, t.label, 1, threshold_grey);
    y += 16;
  }
}

}  // namespace

tracer::Image plot_image(const LinePlot& plot, int width, int height) {
  if (width < 64 || height < 64 || width > 8192 || height > 8192)
    throw std::invalid_argument("plot image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " not within 64..8192");
  Canvas c(width, height, {255, 255, 255});
  const PlotGeometry g(plot, {0, 0, static_cast<double>(width), static_cast<double>(height)}, 6.0);
  draw_axes(c, g);
  draw_data(c, plot, g);
  draw_labels(c, plot, g);
  draw_legend(c, plot, g);
  return c.image();
}

}  // namespace viz
