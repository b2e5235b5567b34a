// A line plot's panel drawn on cairo; see plot_panel.hpp.
#include "app/viz/plot_panel.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "app/viz/drawing.hpp"

namespace viz::detail {
namespace {

constexpr Rgb8 ink{51, 51, 51};
constexpr Rgb8 frame_grey{68, 68, 68};
constexpr Rgb8 grid_grey{221, 221, 221};
constexpr Rgb8 threshold_grey{119, 119, 119};
constexpr double title_pad = 4;  // between a title and its panel's sides

Rgb8 parse_hex(const std::string& s, Rgb8 fallback) {
  if (s.size() != 7 || s[0] != '#') return fallback;
  Rgb8 c;
  std::uint8_t* parts[3] = {&c.r, &c.g, &c.b};
  for (int i = 0; i < 3; ++i) {
    int v = 0;
    for (char ch : s.substr(1 + 2 * i, 2)) {
      const int d = ch >= '0' && ch <= '9'   ? ch - '0'
                    : ch >= 'a' && ch <= 'f' ? ch - 'a' + 10
                    : ch >= 'A' && ch <= 'F' ? ch - 'A' + 10
                                             : -1;
      if (d < 0) return fallback;
      v = v * 16 + d;
    }
    *parts[i] = static_cast<std::uint8_t>(v);
  }
  return c;
}

Rgb8 colour_of(const Series& s, std::size_t index) {
  return parse_hex(s.colour, series_colour(static_cast<int>(index)));
}

void stroke_line(cairo_t* cr, Point a, Point b) {
  cairo_move_to(cr, a.x, a.y);
  cairo_line_to(cr, b.x, b.y);
  cairo_stroke(cr);
}

void set_dash(cairo_t* cr, LineStyle style) {
  static constexpr double dashes[] = {6, 4};
  cairo_set_dash(cr, dashes, style == LineStyle::dashed ? 2 : 0, 0);
}

void set_threshold_stroke(cairo_t* cr) {
  static constexpr double dashes[] = {2, 3};
  set_colour(cr, threshold_grey);
  cairo_set_line_width(cr, 1);
  cairo_set_dash(cr, dashes, 2, 0);
}

void draw_grid_and_frame(cairo_t* cr, const PlotGeometry& g) {
  const Rect& a = g.area();
  set_colour(cr, grid_grey);
  cairo_set_line_width(cr, 1);
  for (double v : g.x_ticks().values) stroke_line(cr, {g.x(v), a.top}, {g.x(v), a.bottom()});
  for (double v : g.y_ticks().values) stroke_line(cr, {a.left, g.y(v)}, {a.right(), g.y(v)});
  // The frame goes under the data, so that points on the border stay visible.
  set_colour(cr, frame_grey);
  cairo_rectangle(cr, a.left, a.top, a.width, a.height);
  cairo_stroke(cr);
}

void draw_tick_labels(cairo_t* cr, const PlotGeometry& g) {
  const Rect& a = g.area();
  set_colour(cr, ink);
  for (std::size_t i = 0; i < g.x_ticks().values.size(); ++i)
    show_text(cr, g.x(g.x_ticks().values[i]), a.bottom() + 15, g.x_ticks().labels[i], {detail::tick_font},
              Align::centre);
  for (std::size_t i = 0; i < g.y_ticks().values.size(); ++i)
    show_text(cr, a.left - 5, g.y(g.y_ticks().values[i]) + 4, g.y_ticks().labels[i], {detail::tick_font}, Align::right);
}

void draw_data(cairo_t* cr, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  cairo_save(cr);
  // A little wider than the area so that markers on the border show whole.
  cairo_rectangle(cr, a.left - 4, a.top - 4, a.width + 8, a.height + 8);
  cairo_clip(cr);
  cairo_save(cr);
  set_threshold_stroke(cr);
  for (const Threshold& t : plot.thresholds)
    if (g.drawable(t)) stroke_line(cr, {a.left, g.y(t.y)}, {a.right(), g.y(t.y)});
  cairo_restore(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_width(cr, 2);
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const Series& s = plot.series[i];
    const std::vector<Point> pts = g.pixels(s);
    set_colour(cr, colour_of(s, i));
    set_dash(cr, s.style);
    for (const Point& p : pts) cairo_line_to(cr, p.x, p.y);
    cairo_stroke(cr);
    if (!s.markers) continue;
    for (const Point& p : pts) {
      cairo_new_sub_path(cr);
      cairo_arc(cr, p.x, p.y, 3, 0, 6.283185307179586);
    }
    cairo_fill(cr);
  }
  cairo_restore(cr);
}

void draw_labels(cairo_t* cr, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& a = g.area();
  const Rect& p = g.panel();
  if (!plot.title.empty()) {
    const auto [text, font] =
        detail::fit_text(plot.title, {detail::title_font_max, true}, detail::title_font_min, p.width - 2 * title_pad);
    const double w = detail::text_width(text, font);
    // Centred over the data area, unless that would push it off the panel.
    const double x = std::clamp(a.left + a.width / 2, p.left + title_pad + w / 2,
                                std::max(p.left + title_pad + w / 2, p.right() - title_pad - w / 2));
    set_colour(cr, {0, 0, 0});
    show_text(cr, x, p.top + 20, text, font, Align::centre);
  }
  set_colour(cr, {0, 0, 0});
  show_text(cr, a.left + a.width / 2, a.bottom() + 34, plot.x_label, {detail::label_font}, Align::centre);
  detail::show_text_upwards(cr, p.left + 12, a.top + a.height / 2, plot.y_label, {detail::label_font});
}

void draw_legend(cairo_t* cr, const LinePlot& plot, const PlotGeometry& g) {
  const Rect& l = g.legend();
  if (l.width <= 0) return;
  double y = l.top + 12;
  cairo_save(cr);
  cairo_set_line_width(cr, 2);
  for (std::size_t i = 0; i < plot.series.size() && g.legend_lists_series(); ++i) {
    const Series& s = plot.series[i];
    if (s.name.empty()) continue;
    set_colour(cr, colour_of(s, i));
    set_dash(cr, s.style);
    stroke_line(cr, {l.left, y - 4}, {l.left + 24, y - 4});
    set_colour(cr, ink);
    show_text(cr, l.left + 30, y, s.name, {detail::legend_font});
    y += detail::legend_step;
  }
  for (const Threshold& t : plot.thresholds) {
    if (t.label.empty() || !g.drawable(t)) continue;
    set_threshold_stroke(cr);
    stroke_line(cr, {l.left, y - 4}, {l.left + 24, y - 4});
    set_colour(cr, {85, 85, 85});
    show_text(cr, l.left + 30, y, t.label, {detail::legend_font});
    y += detail::legend_step;
  }
  cairo_restore(cr);
}

}  // namespace

void draw_panel(cairo_t* cr, const LinePlot& plot, Rect panel) {
  const PlotGeometry g(plot, panel);
  draw_grid_and_frame(cr, g);
  draw_data(cr, plot, g);
  draw_tick_labels(cr, g);
  draw_labels(cr, plot, g);
  draw_legend(cr, plot, g);
}

}  // namespace viz::detail
