// Farming timeline: rows and lanes, tiles merged where they are narrower than
// a pixel, a time axis and a colour bar. See timeline.hpp.
#include "app/viz/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "app/viz/colour.hpp"
#include "app/viz/legend.hpp"
#include "app/viz/svg.hpp"
#include "app/viz/ticks.hpp"

namespace viz {
namespace {

constexpr int max_rows = 4096;
constexpr double width = 760, left = 64, right = 24, plot_width = width - left - right;

// One drawn bar: a tile, or consecutive sub-pixel tiles of one worker.
struct Bar {
  const TimelineTile* first = nullptr;
  int tiles = 0;
  std::uint64_t items = 0;
  std::uint64_t requests = 0;
  double start = 0, end = 0;

  double rate() const { return items ? static_cast<double>(requests) / static_cast<double>(items) : 0.0; }
};

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

// Bars lane by lane: each lane's tiles in order of start, a tile joining the
// previous bar when both are narrower than a pixel and touch it.
std::vector<Bar> bars_of(const Timeline& t, double pixels_per_second) {
  std::vector<const TimelineTile*> order;
  for (const TimelineTile& tile : t.tiles) order.push_back(&tile);
  std::stable_sort(order.begin(), order.end(), [](const TimelineTile* a, const TimelineTile* b) {
    return std::tie(a->node, a->worker, a->start) < std::tie(b->node, b->worker, b->start);
  });
  std::vector<Bar> bars;
  for (const TimelineTile* tile : order) {
    const double tile_px = (tile->end - tile->start) * pixels_per_second;
    if (!bars.empty()) {
      Bar& bar = bars.back();
      const bool same_lane = bar.first->node == tile->node && bar.first->worker == tile->worker;
      const bool bar_thin = (bar.end - bar.start) * pixels_per_second < 1.0;
      const bool touching = (tile->start - bar.end) * pixels_per_second < 0.5;
      if (same_lane && bar_thin && tile_px < 1.0 && touching) {
        ++bar.tiles;
        bar.items += tile->items;
        bar.requests += tile->page_requests;
        bar.end = std::max(bar.end, tile->end);
        continue;
      }
    }
    bars.push_back({tile, 1, tile->items, tile->page_requests, tile->start, tile->end});
  }
  return bars;
}

std::string describe(const Bar& bar) {
  const TimelineTile& t = *bar.first;
  std::string s = "node " + std::to_string(t.node) + ", worker " + std::to_string(t.worker) + ": ";
  if (bar.tiles == 1)
    s += "items " + std::to_string(t.first_item) + ".." + std::to_string(t.first_item + t.items - 1) + " (" +
         std::to_string(t.items) + ")";
  else
    s += std::to_string(bar.tiles) + " tiles, " + std::to_string(bar.items) + " items";
  return s + ", " + format_number(bar.start) + " to " + format_number(bar.end) + " s, " +
         std::to_string(bar.requests) + " page requests";
}

}  // namespace

std::string timeline_svg(const Timeline& t) {
  validate(t);
  double last_end = 0;
  for (const TimelineTile& tile : t.tiles) last_end = std::max(last_end, tile.end);
  const Ticks ticks = make_ticks(AxisScale::linear, 0.0, last_end > 0 ? last_end : 1.0);
  const double pixels_per_second = plot_width / (ticks.hi - ticks.lo);
  const auto x_of = [&](double seconds) { return left + (seconds - ticks.lo) * pixels_per_second; };

  const double row_h = std::clamp(480.0 / t.nodes, 3.0, 18.0);
  const double lane_h = row_h / t.workers_per_node;
  const double title_h = t.title.empty() ? 10.0 : 34.0;
  const double axis_y = title_h + t.nodes * row_h;
  SvgDocument doc(width, axis_y + 96);
  doc.leaf("rect", {{"width", "100%"}, {"height", "100%"}, {"fill", "white"}});
  if (!t.title.empty())
    doc.text(t.title, {{"x", num(width / 2)}, {"y", "22"}, {"text-anchor", "middle"}, {"font-size", "15"},
                       {"font-weight", "bold"}});

  // Rows, shaded alternately, labelled as often as they have room for.
  int label_step = 1;
  while (label_step * row_h < 10) label_step *= 2;
  doc.open("g", {{"class", "rows"}});
  for (int n = 0; n < t.nodes; ++n) {
    const double y = title_h + n * row_h;
    doc.leaf("rect", {{"class", "row"}, {"x", num(left)}, {"y", num(y)}, {"width", num(plot_width)},
                      {"height", num(row_h)}, {"fill", n % 2 ? "#f3f3f3" : "#fbfbfb"}});
    if (n % label_step == 0)
      doc.text("node " + std::to_string(n), {{"x", num(left - 6)}, {"y", num(y + row_h / 2 + 4)},
                                             {"text-anchor", "end"}, {"font-size", "11"}});
  }
  doc.close();

  const std::vector<Bar> bars = bars_of(t, pixels_per_second);
  double max_rate = 0;
  for (const Bar& bar : bars) max_rate = std::max(max_rate, bar.rate());
  const double pad = lane_h >= 4 ? 0.5 : 0.0;
  doc.open("g", {{"class", "tiles"}});
  for (const Bar& bar : bars) {
    const double y = title_h + bar.first->node * row_h + bar.first->worker * lane_h + pad;
    doc.open("rect", {{"class", "tile"}, {"x", num(x_of(bar.start))}, {"y", num(y)},
                      {"width", num(std::max(0.5, (bar.end - bar.start) * pixels_per_second))},
                      {"height", num(std::max(1.0, lane_h - 2 * pad))},
                      {"fill", hex(work_scale(max_rate > 0 ? bar.rate() / max_rate : 0.0))}});
    doc.title(describe(bar));
    doc.close();
  }
  doc.close();

  doc.open("g", {{"class", "axis"}});
  doc.leaf("line", {{"x1", num(left)}, {"y1", num(axis_y)}, {"x2", num(left + plot_width)}, {"y2", num(axis_y)},
                    {"stroke", "#333333"}});
  for (std::size_t i = 0; i < ticks.values.size(); ++i) {
    const double x = x_of(ticks.values[i]);
    doc.leaf("line", {{"x1", num(x)}, {"y1", num(axis_y)}, {"x2", num(x)}, {"y2", num(axis_y + 5)},
                      {"stroke", "#333333"}});
    doc.text(ticks.labels[i], {{"x", num(x)}, {"y", num(axis_y + 18)}, {"text-anchor", "middle"}, {"font-size", "11"}});
  }
  doc.text(t.time_axis, {{"x", num(left + plot_width / 2)}, {"y", num(axis_y + 36)}, {"text-anchor", "middle"},
                         {"font-size", "12"}});
  doc.close();

  doc.open("g", {{"class", "legend"}});
  doc.open("defs", {});
  scale_gradient(doc, "viz-work-scale", work_scale);
  doc.close();
  const double legend_y = axis_y + 56;
  colour_bar(doc, left, legend_y, "viz-work-scale", "bar colour: page requests per item", max_rate);
  doc.text("one row per processor, one lane per pixel computer; a bar from a tile's start to its end",
           {{"x", num(left + 200)}, {"y", num(legend_y + 16)}, {"font-size", "11"}});
  doc.close();
  return doc.finish();
}

}  // namespace viz
