// Farming timeline: rows and lanes, tiles merged where they are narrower than
// a pixel, a time axis and a colour bar, drawn on cairo. See timeline.hpp.
#include "app/viz/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "app/viz/drawing.hpp"
#include "app/viz/legend.hpp"
#include "app/viz/ticks.hpp"

namespace viz {
namespace {

using detail::Align;
using detail::set_colour;
using detail::show_text;

constexpr int max_rows = 4096;
constexpr double width = 760, left = 64, right = 28, plot_width = width - left - right;

void validate(const Timeline& t) {
  if (t.nodes < 1 || t.nodes > max_rows)
    throw std::invalid_argument("timeline: " + std::to_string(t.nodes) + " nodes, not in 1.." +
                                std::to_string(max_rows));
  if (t.workers_per_node < 1 || t.workers_per_node > max_rows)
    throw std::invalid_argument("timeline: " + std::to_string(t.workers_per_node) + " workers per node, not in 1.." +
                                std::to_string(max_rows));
  for (const TimelineTile& tile : t.tiles) {
    if (tile.node < 0 || tile.node >= t.nodes || tile.worker < 0 || tile.worker >= t.workers_per_node)
      throw std::invalid_argument("timeline: a tile of worker " + std::to_string(tile.worker) + " on node " +
                                  std::to_string(tile.node) + ", outside the machine");
    if (!std::isfinite(tile.start) || !std::isfinite(tile.end) || tile.start < 0 || tile.end < tile.start)
      throw std::invalid_argument("timeline: a tile of node " + std::to_string(tile.node) + " from " +
                                  std::to_string(tile.start) + " s to " + std::to_string(tile.end) + " s");
  }
}

// Where everything goes, decided before drawing.
struct Layout {
  Ticks ticks;
  double pixels_per_second = 1;
  double row_h = 1, lane_h = 1, title_h = 0, axis_y = 0, height = 0;
  std::vector<TimelineBar> bars;
  double max_rate = 0;  // page requests per item, over the bars

  double x_of(double seconds) const { return left + (seconds - ticks.lo) * pixels_per_second; }
};

double rate(const TimelineBar& b) {
  return b.items ? static_cast<double>(b.page_requests) / static_cast<double>(b.items) : 0.0;
}

// Bars lane by lane: each lane's tiles in order of start, a tile joining the
// previous bar when both are narrower than a pixel and touch it.
std::vector<TimelineBar> merge_tiles(const Timeline& t, double pixels_per_second) {
  std::vector<const TimelineTile*> order;
  for (const TimelineTile& tile : t.tiles) order.push_back(&tile);
  std::stable_sort(order.begin(), order.end(), [](const TimelineTile* a, const TimelineTile* b) {
    return std::tie(a->node, a->worker, a->start) < std::tie(b->node, b->worker, b->start);
  });
  std::vector<TimelineBar> bars;
  for (const TimelineTile* tile : order) {
    const double tile_px = (tile->end - tile->start) * pixels_per_second;
    if (!bars.empty()) {
      TimelineBar& bar = bars.back();
      const bool same_lane = bar.node == tile->node && bar.worker == tile->worker;
      const bool bar_thin = (bar.end - bar.start) * pixels_per_second < 1.0;
      const bool touching = (tile->start - bar.end) * pixels_per_second < 0.5;
      if (same_lane && bar_thin && tile_px < 1.0 && touching) {
        ++bar.tiles;
        bar.items += tile->items;
        bar.page_requests += tile->page_requests;
        bar.end = std::max(bar.end, tile->end);
        continue;
      }
    }
    bars.push_back({.node = tile->node,
                    .worker = tile->worker,
                    .tiles = 1,
                    .items = tile->items,
                    .page_requests = tile->page_requests,
                    .start = tile->start,
                    .end = tile->end});
  }
  return bars;
}

Layout layout_of(const Timeline& t) {
  validate(t);
  Layout l;
  double last_end = 0;
  for (const TimelineTile& tile : t.tiles) last_end = std::max(last_end, tile.end);
  l.ticks = make_ticks(AxisScale::linear, 0.0, last_end > 0 ? last_end : 1.0);
  l.pixels_per_second = plot_width / (l.ticks.hi - l.ticks.lo);
  // Taller rows for more lanes, as long as the machine stays about 480 px high.
  l.row_h = std::clamp(480.0 / t.nodes, 3.0, std::max(18.0, 8.0 * std::min(t.workers_per_node, 8)));
  l.lane_h = l.row_h / t.workers_per_node;
  l.title_h = t.title.empty() ? 10.0 : 34.0;
  l.axis_y = l.title_h + t.nodes * l.row_h;
  l.height = l.axis_y + 96;
  l.bars = merge_tiles(t, l.pixels_per_second);
  for (const TimelineBar& b : l.bars) l.max_rate = std::max(l.max_rate, rate(b));
  const double pad = l.lane_h >= 4 ? 0.5 : 0.0;
  for (TimelineBar& b : l.bars) {
    b.x = l.x_of(b.start);
    b.y = l.title_h + b.node * l.row_h + b.worker * l.lane_h + pad;
    b.width = std::max(0.5, (b.end - b.start) * l.pixels_per_second);
    b.height = std::max(1.0, l.lane_h - 2 * pad);
    b.fill = work_scale(l.max_rate > 0 ? rate(b) / l.max_rate : 0.0);
  }
  return l;
}

// Rows shaded alternately and labelled as often as they have room for;
// lanes of one row parted by a line, and named where they are tall enough.
void draw_rows(cairo_t* cr, const Timeline& t, const Layout& l) {
  int label_step = 1;
  while (label_step * l.row_h < 10) label_step *= 2;
  for (int n = 0; n < t.nodes; ++n) {
    const double y = l.title_h + n * l.row_h;
    set_colour(cr, n % 2 ? Rgb8{243, 243, 243} : Rgb8{251, 251, 251});
    cairo_rectangle(cr, left, y, plot_width, l.row_h);
    cairo_fill(cr);
    set_colour(cr, {0, 0, 0});
    if (n % label_step == 0)
      show_text(cr, left - 6, y + l.row_h / 2 + 4, "node " + std::to_string(n), {11}, Align::right);
  }
  if (t.workers_per_node < 2 || l.lane_h < 2) return;
  set_colour(cr, {200, 200, 200});
  cairo_set_line_width(cr, std::min(1.0, l.lane_h / 4));
  for (int n = 0; n < t.nodes; ++n)
    for (int w = 1; w < t.workers_per_node; ++w) {
      const double y = l.title_h + n * l.row_h + w * l.lane_h;
      cairo_move_to(cr, left, y);
      cairo_line_to(cr, left + plot_width, y);
    }
  cairo_stroke(cr);
  if (l.lane_h < 8) return;
  set_colour(cr, {85, 85, 85});
  const double size = std::min(10.0, l.lane_h - 1);
  for (int w = 0; w < t.workers_per_node; ++w) {
    std::string name = std::to_string(w);
    name.insert(name.begin(), 'w');
    for (int n = 0; n < t.nodes; ++n)
      show_text(cr, left + plot_width + 3, l.title_h + n * l.row_h + (w + 0.5) * l.lane_h + 0.35 * size, name, {size});
  }
}

void draw_axis(cairo_t* cr, const Timeline& t, const Layout& l) {
  set_colour(cr, {51, 51, 51});
  cairo_set_line_width(cr, 1);
  cairo_move_to(cr, left, l.axis_y);
  cairo_line_to(cr, left + plot_width, l.axis_y);
  for (double v : l.ticks.values) {
    cairo_move_to(cr, l.x_of(v), l.axis_y);
    cairo_line_to(cr, l.x_of(v), l.axis_y + 5);
  }
  cairo_stroke(cr);
  set_colour(cr, {0, 0, 0});
  for (std::size_t i = 0; i < l.ticks.values.size(); ++i)
    show_text(cr, l.x_of(l.ticks.values[i]), l.axis_y + 18, l.ticks.labels[i], {11}, Align::centre);
  show_text(cr, left + plot_width / 2, l.axis_y + 36, t.time_axis, {12}, Align::centre);
}

void draw_timeline(cairo_t* cr, const Timeline& t, const Layout& l) {
  if (!t.title.empty()) {
    const auto [text, font] = detail::fit_text(t.title, {15, true}, 11, width - 16);
    set_colour(cr, {0, 0, 0});
    show_text(cr, width / 2, 22, text, font, Align::centre);
  }
  draw_rows(cr, t, l);
  for (const TimelineBar& b : l.bars) {
    set_colour(cr, b.fill);
    cairo_rectangle(cr, b.x, b.y, b.width, b.height);
    cairo_fill(cr);
  }
  draw_axis(cr, t, l);
  const double legend_y = l.axis_y + 56;
  detail::colour_bar(cr, left, legend_y, work_scale, "bar colour: page requests per item", l.max_rate);
  set_colour(cr, {0, 0, 0});
  const double note_x = left + detail::colour_bar_width + 100;
  if (t.workers_per_node > 1) {
    show_text(cr, note_x, legend_y + 4, "one row per processor, one lane per pixel computer (w0 at the top);", {11});
    show_text(cr, note_x, legend_y + 20, "a bar from a tile's start to its end", {11});
  } else {
    show_text(cr, note_x, legend_y + 12, "one row per processor; a bar from a tile's start to its end", {11});
  }
}

}  // namespace

std::string timeline_svg(const Timeline& t) {
  const Layout l = layout_of(t);
  return detail::draw_svg("timeline SVG", width, l.height, [&](cairo_t* cr) { draw_timeline(cr, t, l); });
}

std::string timeline_pdf(const Timeline& t) {
  const Layout l = layout_of(t);
  return detail::draw_pdf("timeline PDF", width, l.height, [&](cairo_t* cr) { draw_timeline(cr, t, l); });
}

tracer::Image timeline_image(const Timeline& t) {
  const Layout l = layout_of(t);
  return detail::draw_image("timeline image", static_cast<int>(width), static_cast<int>(std::ceil(l.height)),
                            [&](cairo_t* cr) { draw_timeline(cr, t, l); });
}

std::vector<TimelineBar> timeline_bars(const Timeline& t) { return layout_of(t).bars; }

}  // namespace viz
