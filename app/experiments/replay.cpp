// The replay page's data and markup (see replay.hpp); the script that plays
// it and its style are in replay.js and replay.css beside it.
#include "app/experiments/replay.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

#include "app/experiments/machine_pictures.hpp"
#include "app/render/run_report.hpp"
#include "app/viz/colour.hpp"
#include "app/viz/html_report.hpp"
#include "app/viz/machine_drawing.hpp"
#include "app/viz/svg.hpp"
#include "nodes/machine/messages.hpp"
#include "nodes/machine/pixel_order.hpp"

namespace app {
namespace {

// The tick: the power of ten from 1 ns up that keeps the run's end under
// 10^9 ticks, so that every time is an integer of at most ten digits (a
// double holds it exactly, and the page's JSON stays small).
double tick_for(double end) {
  double tick = 1e-9;
  while (end / tick > 1e9) tick *= 10;
  return tick;
}

struct Ticks {
  double tick;
  long long operator()(double seconds) const { return std::llround(seconds / tick); }
};

Json packets_json(const nodes::Recording& rec, const Ticks& ticks) {
  Json kind = Json::array(), bytes = Json::array(), hops = Json::array(), id = Json::array(), route = Json::array(),
       times = Json::array();
  for (const nodes::PacketTrace& p : rec.packets) {
    kind.push_back(p.kind);
    bytes.push_back(p.bytes);
    hops.push_back(p.hops());
    id.push_back(p.id);
    for (const topology::NodeId n : p.route) route.push_back(n);
    // Rounded first, then differenced: the deltas are never negative.
    long long previous = 0;
    for (std::size_t i = 0; i < p.times.size(); ++i) {
      const long long t = ticks(p.times[i]);
      times.push_back(i == 0 ? t : t - previous);
      previous = t;
    }
  }
  return {{"kind", kind}, {"bytes", bytes}, {"hops", hops}, {"id", id}, {"route", route}, {"times", times}};
}

struct TileRow {
  std::size_t node;
  const nodes::TileSpan* span;
};

// Every tile, in the order their results left.
std::vector<TileRow> tiles_by_end(const nodes::Recording& rec) {
  std::vector<TileRow> rows;
  for (std::size_t n = 0; n < rec.nodes.size(); ++n)
    for (const nodes::TileSpan& s : rec.nodes[n].tiles) rows.push_back({n, &s});
  std::stable_sort(rows.begin(), rows.end(), [](const TileRow& a, const TileRow& b) {
    return std::tie(a.span->end, a.node) < std::tie(b.span->end, b.node);
  });
  return rows;
}

Json tiles_json(const std::vector<TileRow>& rows, const Ticks& ticks) {
  Json node = Json::array(), worker = Json::array(), first = Json::array(), count = Json::array(),
       start = Json::array(), end = Json::array(), misses = Json::array();
  for (const TileRow& r : rows) {
    node.push_back(r.node);
    worker.push_back(r.span->worker);
    first.push_back(r.span->tile.first);
    count.push_back(r.span->tile.count);
    start.push_back(ticks(r.span->start));
    end.push_back(ticks(r.span->end));
    misses.push_back(r.span->page_requests);
  }
  return {{"node", node},   {"worker", worker}, {"first", first},  {"count", count},
          {"start", start}, {"end", end},       {"misses", misses}};
}

// Page hits per tile: each sample's rise over its worker's previous one.
Json hits_json(const nodes::Recording& rec, const Ticks& ticks) {
  Json node = Json::array(), time = Json::array(), hits = Json::array();
  for (std::size_t n = 0; n < rec.nodes.size(); ++n) {
    std::map<std::uint16_t, std::uint64_t> before;
    for (const nodes::HitSample& h : rec.nodes[n].hits) {
      node.push_back(n);
      time.push_back(ticks(h.time));
      hits.push_back(h.hits - before[h.worker]);
      before[h.worker] = h.hits;
    }
  }
  return {{"node", node}, {"time", time}, {"hits", hits}};
}

Json fetches_json(const nodes::Recording& rec, const Ticks& ticks) {
  Json node = Json::array(), worker = Json::array(), page = Json::array(), start = Json::array(), end = Json::array();
  for (std::size_t n = 0; n < rec.nodes.size(); ++n)
    for (const nodes::FetchEvent& f : rec.nodes[n].fetches) {
      node.push_back(n);
      worker.push_back(f.worker);
      page.push_back(f.page);
      start.push_back(ticks(f.start));
      end.push_back(ticks(f.end));
    }
  return {{"node", node}, {"worker", worker}, {"page", page}, {"start", start}, {"end", end}};
}

Json serves_json(const nodes::Recording& rec, const Ticks& ticks) {
  Json node = Json::array(), page = Json::array(), to = Json::array(), start = Json::array(), end = Json::array();
  for (std::size_t n = 0; n < rec.nodes.size(); ++n)
    for (const nodes::ServeEvent& s : rec.nodes[n].serves) {
      node.push_back(n);
      page.push_back(s.page);
      to.push_back(s.to);
      start.push_back(ticks(s.start));
      end.push_back(ticks(s.end));
    }
  return {{"node", node}, {"page", page}, {"to", to}, {"start", start}, {"end", end}};
}

// Which tile (its place in `rows`, plus one; 0: none) computed each pixel,
// as 24-bit colours of a PNG: a few KB for a frame of compact tiles.
tracer::Image tile_map(const nodes::MachineReport& report, const std::vector<TileRow>& rows, int width, int height) {
  const bool corners = report.items != static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  const int grid_width = width + (corners ? 1 : 0), grid_rows = height + (corners ? 1 : 0);
  const std::vector<std::uint32_t> positions = nodes::item_positions(grid_width, grid_rows, report.pixel_order);
  tracer::Image map(width, height);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const nodes::Tile tile = rows[r].span->tile;
    const auto value = static_cast<std::uint32_t>(r + 1);
    const tracer::Color colour{float((value >> 16) & 255) / 255.0f, float((value >> 8) & 255) / 255.0f,
                               float(value & 255) / 255.0f};
    for (std::uint32_t item = tile.first; item < tile.first + tile.count; ++item) {
      const std::uint32_t position = nodes::scanline_position(positions, item);
      const int x = static_cast<int>(position % grid_width), y = static_cast<int>(position / grid_width);
      if (x < width && y < height) map.at(x, y) = colour;
    }
  }
  return map;
}

// The machine picture with nothing on it yet: node labels and idle links,
// the stage the page draws the run on.
viz::MachineDrawing stage(const nodes::MachineReport& report) {
  viz::MachineDrawing m = machine_drawing(report);
  m.title = report.topology.spec() + ": the run replayed";
  for (viz::NodeWork& n : m.nodes) n = viz::NodeWork{};
  for (viz::LinkTraffic& l : m.links) l.packets = l.bytes = 0;
  return m;
}

std::string script_json(const Json& data) {
  // "</" would end the script element early; JSON allows "<\/".
  std::string text = dump_json(data);
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') out += '\\';
  }
  return out;
}

}  // namespace

Json replay_data(const ReplaySource& source) {
  if (source.report == nullptr || source.report->recording == nullptr || source.image == nullptr)
    throw std::invalid_argument("replay: the run was not recorded");
  const nodes::MachineReport& report = *source.report;
  const nodes::Recording& rec = *report.recording;
  const Ticks ticks{tick_for(rec.end)};
  const std::vector<TileRow> rows = tiles_by_end(rec);
  const viz::MachineDrawing drawing = stage(report);
  Json places = Json::array();
  for (const viz::NodePlace& p : viz::machine_node_places(drawing)) places.push_back({p.x, p.y, p.radius});
  Json links = Json::array();
  for (const nodes::LinkStats& l : report.network.links) links.push_back({l.from, l.to});
  Json kinds = Json::array();
  for (int k = 0; k < nodes::message_kind_count; ++k)
    kinds.push_back(k == 0 ? std::string() : std::string(nodes::message_kind_name(static_cast<std::uint8_t>(k))));
  Json colours = Json::array();
  for (int n = 0; n < report.nodes; ++n) colours.push_back(viz::hex(viz::node_colour(n)));
  Json unrecorded_by_kind = Json::object();
  for (std::size_t k = 0; k < rec.unrecorded.size(); ++k)
    if (rec.unrecorded[k])
      unrecorded_by_kind[std::string(nodes::message_kind_name(static_cast<std::uint8_t>(k)))] = rec.unrecorded[k];
  const int width = source.image->width(), height = source.image->height();
  return {{"title", source.title},
          {"topology", report.topology.spec()},
          {"nodes", report.nodes},
          {"workers", report.workers_per_node},
          {"timing", rec.virtual_time ? "virtual" : "real"},
          {"tick", ticks.tick},
          {"end", ticks(rec.end)},
          {"seconds", report.model ? report.predicted_seconds : report.wall_seconds},
          {"kinds", kinds},
          {"colours", colours},
          {"places", places},
          {"links", links},
          {"packets", packets_json(rec, ticks)},
          {"tiles", tiles_json(rows, ticks)},
          {"fetches", fetches_json(rec, ticks)},
          {"serves", serves_json(rec, ticks)},
          {"hits", hits_json(rec, ticks)},
          {"maxPackets", rec.max_packets},
          {"ranks", rec.node_rank},
          {"unrecorded",
           {{"packets", rec.unrecorded_packets},
            {"hops", rec.unrecorded_hops},
            {"fetches", rec.unrecorded_fetches},
            {"serves", rec.unrecorded_serves},
            {"byKind", unrecorded_by_kind}}},
          {"window", ticks(rec.window)},
          {"totals",
           {{"packets", report.network.hops.packets},
            {"hops", report.network.hops.total_hops},
            {"misses", report.svm().misses},
            {"pixels", report.items_computed()}}},
          {"image",
           {{"width", width},
            {"height", height},
            {"colours", viz::png_data_url(*source.image)},
            {"tiles", viz::png_data_url(tile_map(report, rows, width, height))}}}};
}

std::string replay_page(const ReplaySource& source) {
  const Json data = replay_data(source);
  const std::string machine = viz::machine_svg(stage(*source.report));
  std::string made;
  if (!source.made_by.empty() || !source.command_line.empty()) {
    made = "<p class=\"made\">" +
           std::string(source.made_by.empty() ? "Made" : "Made by " + viz::escape_xml(source.made_by));
    if (!source.command_line.empty())
      made += " with <code>" + viz::escape_xml(viz::shell_quoted(source.command_line)) + "</code>";
    made += "</p>\n";
  }
  const std::string title = viz::escape_xml(source.title) + ": a replay of the run";
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>" + title +
         "</title>\n<style>\n" + replay_style + "</style>\n</head>\n<body>\n<h1>" + title + "</h1>\n" + made +
         "<p id=\"about\"></p>\n<p id=\"bound\" hidden></p>\n"
         "<div id=\"controls\">"
         "<button id=\"play\">play</button> <button id=\"back\" title=\"the previous event\">&#9664; step</button> "
         "<button id=\"step\" title=\"the next event: a packet injected, crossing a link or delivered\">step "
         "&#9654;</button> <button id=\"end\">end</button> "
         "<label>speed <select id=\"speed\"></select></label> "
         "<input id=\"slider\" type=\"range\" min=\"0\" max=\"1000\" value=\"0\"/> <span id=\"clock\"></span>"
         "</div>\n<div id=\"counters\"></div>\n"
         "<div id=\"panes\">\n<div id=\"stage\">" +
         machine +
         "<canvas id=\"overlay\"></canvas></div>\n"
         "<div id=\"picture\"><canvas id=\"frame\"></canvas><br/>"
         "<label><input type=\"radio\" name=\"view\" value=\"pixels\" checked/> pixels</label> "
         "<label><input type=\"radio\" name=\"view\" value=\"owners\"/> owners</label></div>\n</div>\n"
         "<div id=\"legend\"></div>\n<div id=\"details\"><p>Click a node for its cache and the pages it served, "
         "or a packet in flight for its route.</p></div>\n"
         "<script type=\"application/json\" id=\"replay-data\">" +
         script_json(data) + "</script>\n<script>\n" + replay_script + "</script>\n</body>\n</html>\n";
}

}  // namespace app
