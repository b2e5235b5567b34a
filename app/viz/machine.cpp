// Machine drawing: layout in "units" (neighbouring nodes about one unit
// apart), then one affine map to pixels. See machine.hpp for the layouts.
#include "app/viz/machine.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "app/viz/legend.hpp"
#include "app/viz/svg.hpp"

namespace viz {
namespace {

struct Vec2 {
  double x = 0, y = 0;
  Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
  Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
  Vec2 operator*(double s) const { return {x * s, y * s}; }
};

constexpr double node_radius = 0.3;  // units
constexpr double margin = 1.0;       // units around the layout: room for bows and wrap arcs
constexpr double label_em = 0.85;    // label font size per node radius
constexpr double min_label_px = 10;  // the picture grows to keep labels this large...
constexpr double max_extent = 1400;  // ...but no larger than this, in pixels
constexpr std::size_t max_detailed_links = 4096;  // beyond: links drawn in bulk
constexpr int traffic_bands = 16;                 // bulk links: one element per band
constexpr const char* idle_grey = "#cccccc";

// Distance between the two halves of hypercube level `level` along one axis:
// each level's gap grows so that every sub-cube is visibly a block.
double cube_offset(int level) {
  double width = 0.0, offset = 1.0;
  for (int j = 0; j < level; ++j) {
    width += offset;
    offset = width + 1.0 + 0.5 * (j + 1);
  }
  return offset;
}

std::vector<Vec2> layout(const MachineDrawing& m, int n) {
  std::vector<Vec2> pos(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Vec2& p = pos[static_cast<std::size_t>(i)];
    if (m.kind == MachineKind::hypercube) {
      for (int bit = 0; bit < m.dim_a; ++bit)
        if ((i >> bit) & 1) (bit % 2 == 0 ? p.x : p.y) += cube_offset(bit / 2);
    } else if (m.kind == MachineKind::mesh || m.kind == MachineKind::torus) {
      p = {static_cast<double>(i % m.dim_a), static_cast<double>(i / m.dim_a)};
    } else if (n > 1) {
      // Neighbours about a unit apart; a complete graph gets more room for its chords.
      const double r = m.kind == MachineKind::complete ? std::max(2.5, 1.3 * n / (2.0 * std::numbers::pi))
                                                       : std::max(1.5, n / (2.0 * std::numbers::pi));
      const double a = 2.0 * std::numbers::pi * i / n;
      p = {r * std::sin(a), -r * std::cos(a)};
    }
  }
  return pos;
}

void validate(const MachineDrawing& m, int n) {
  if (static_cast<int>(m.nodes.size()) != n)
    throw std::invalid_argument("machine drawing: " + std::to_string(m.nodes.size()) + " nodes given, topology has " +
                                std::to_string(n));
  for (const LinkTraffic& l : m.links)
    if (l.from < 0 || l.from >= n || l.to < 0 || l.to >= n || l.from == l.to)
      throw std::invalid_argument("machine drawing: bad link " + std::to_string(l.from) + " -> " +
                                  std::to_string(l.to) + " on " + std::to_string(n) + " nodes");
}

struct View {
  double scale = 1, left = 0, top = 0;
  Vec2 origin{};  // layout point drawn at (left, top)
  std::string pt(Vec2 p) const {
    return num(left + (p.x - origin.x) * scale) + " " + num(top + (p.y - origin.y) * scale);
  }
};

// Geometry of one directed link: how far it bows (units, along the normal of
// the lower-id -> higher-id direction) and whether it is a torus wrap link.
struct LinkGeometry {
  double bow = 0;
  bool wrap = false;
};

LinkGeometry link_geometry(const MachineDrawing& m, int a, int b) {
  if (m.kind == MachineKind::hypercube) {
    const int bit = std::countr_zero(static_cast<unsigned>(a ^ b));
    const int level = bit / 2;
    if (level == 0) return {};
    // Bow away from the partner row/column so parallel long links stay apart.
    const int partner_bit = bit % 2 == 0 ? 1 : 0;
    const bool first_of_pair = ((a >> partner_bit) & 1) == 0;
    const double sign = (bit % 2 == 0) == first_of_pair ? -1.0 : 1.0;
    return {sign * (0.45 + 0.3 * level), false};
  }
  if (m.kind == MachineKind::torus) {
    const int dx = std::abs(a % m.dim_a - b % m.dim_a), dy = std::abs(a / m.dim_a - b / m.dim_a);
    return {0.0, (m.dim_a > 2 && dx == m.dim_a - 1) || (m.dim_b > 2 && dy == m.dim_b - 1)};
  }
  return {};
}

// Outward direction of a torus wrap link at node p (towards the border it leaves by).
Vec2 wrap_outward(Vec2 p, Vec2 other) {
  if (p.y == other.y) return {p.x < other.x ? -1.0 : 1.0, 0.0};
  return {0.0, p.y < other.y ? -1.0 : 1.0};
}

// A straight line from p to q, as SVG path commands.
std::string line(const View& v, Vec2 p, Vec2 q) {
  std::string d = "M";
  d += v.pt(p);
  d += 'L';
  d += v.pt(q);
  return d;
}

// A quadratic Bezier from p through control c to q, as SVG path commands.
std::string curve(const View& v, Vec2 p, Vec2 c, Vec2 q) {
  std::string d = "M";
  d += v.pt(p);
  d += " Q";
  d += v.pt(c);
  d += ' ';
  d += v.pt(q);
  return d;
}

std::string link_path(const MachineDrawing& m, const std::vector<Vec2>& pos, const LinkTraffic& l,
                      const View& v, double lane) {
  const int a = std::min(l.from, l.to), b = std::max(l.from, l.to);
  const Vec2 pa = pos[static_cast<std::size_t>(a)], pb = pos[static_cast<std::size_t>(b)];
  const Vec2 d = pb - pa;
  const double len = std::hypot(d.x, d.y);
  const Vec2 n{-d.y / len, d.x / len};
  // Right-hand lane of the direction of travel keeps the two directions apart.
  const Vec2 off = n * (l.from == a ? lane : -lane);
  const LinkGeometry g = link_geometry(m, a, b);
  if (!g.wrap && g.bow == 0) return line(v, pa + off, pb + off);
  if (!g.wrap) return curve(v, pa + off, (pa + pb) * 0.5 + n * g.bow + off, pb + off);
  std::string path;
  for (const auto& [p, q] : {std::pair{pa, pb}, std::pair{pb, pa}}) {
    const Vec2 o = wrap_outward(p, q);
    path += curve(v, p + off, p + o * 0.5 + off, p + o * 0.65 + n * 0.3 + off);
    path += ' ';
  }
  path.pop_back();
  return path;
}

struct Scales {
  bool by_bytes = false;        // links measured in bytes (else packets)
  std::uint64_t max_link = 0;   // largest link measure
  std::uint64_t max_pixels = 0;
  std::uint64_t max_requests = 0;
  std::uint64_t measure(const LinkTraffic& l) const { return by_bytes ? l.bytes : l.packets; }
};

Scales scales_of(const MachineDrawing& m) {
  Scales s;
  for (const LinkTraffic& l : m.links) s.by_bytes = s.by_bytes || l.bytes > 0;
  for (const LinkTraffic& l : m.links) s.max_link = std::max(s.max_link, s.measure(l));
  for (const NodeWork& w : m.nodes) {
    s.max_pixels = std::max(s.max_pixels, w.pixels);
    s.max_requests = std::max(s.max_requests, w.page_requests_served);
  }
  return s;
}

double fraction(std::uint64_t v, std::uint64_t max) {
  return max == 0 ? 0.0 : static_cast<double>(v) / static_cast<double>(max);
}

void draw_links(SvgDocument& doc, const MachineDrawing& m, const std::vector<Vec2>& pos, const View& v,
                const Scales& s) {
  const bool complete = m.kind == MachineKind::complete;
  const double lane = complete ? 0.03 : 0.07;
  const double max_width = complete ? 2.5 : std::max(1.5, 0.1 * v.scale);
  auto width = [&](double f) { return num(0.8 + (max_width - 0.8) * f); };
  doc.open("g", {{"class", "links"}, {"fill", "none"}, {"stroke-linecap", "round"}});
  if (m.links.size() > max_detailed_links) {
    // Too many to tell apart or to point at: lightest band first, idle links left out.
    std::vector<std::string> bands(traffic_bands);
    for (const LinkTraffic& l : m.links) {
      if (l.packets == 0) continue;
      const int band = std::min(traffic_bands - 1, static_cast<int>(fraction(s.measure(l), s.max_link) * traffic_bands));
      bands[static_cast<std::size_t>(band)] += link_path(m, pos, l, v, lane);
    }
    for (int b = 0; b < traffic_bands; ++b) {
      if (bands[static_cast<std::size_t>(b)].empty()) continue;
      const double f = (b + 0.5) / traffic_bands;
      doc.leaf("path", {{"class", "link-band"}, {"d", bands[static_cast<std::size_t>(b)]},
                        {"stroke", hex(traffic_scale(f))}, {"stroke-width", width(f)}});
    }
    doc.close();
    return;
  }
  std::vector<const LinkTraffic*> active;
  for (const LinkTraffic& l : m.links) {
    if (l.packets > 0) { active.push_back(&l); continue; }
    doc.leaf("path", {{"class", "idle-link"}, {"d", link_path(m, pos, l, v, 0.0)}, {"stroke", idle_grey},
                      {"stroke-width", "0.8"}});
  }
  // Heaviest links last, so they are drawn on top.
  std::stable_sort(active.begin(), active.end(),
                   [&](const LinkTraffic* x, const LinkTraffic* y) { return s.measure(*x) < s.measure(*y); });
  for (const LinkTraffic* l : active) {
    const double f = fraction(s.measure(*l), s.max_link);
    doc.open("path", {{"class", "link"}, {"d", link_path(m, pos, *l, v, lane)}, {"stroke", hex(traffic_scale(f))},
                      {"stroke-width", width(f)}});
    doc.title(std::to_string(l->from) + " -> " + std::to_string(l->to) + ": " + std::to_string(l->packets) +
              " packets, " + std::to_string(l->bytes) + " bytes");
    doc.close();
  }
  doc.close();
}

void draw_node(SvgDocument& doc, int id, const NodeWork& w, Vec2 centre, const View& v, const Scales& s) {
  const double r = node_radius * v.scale;
  const std::string cx = num(v.left + (centre.x - v.origin.x) * v.scale);
  const std::string cy = num(v.top + (centre.y - v.origin.y) * v.scale);
  const Rgb8 fill = work_scale(fraction(w.pixels, s.max_pixels));
  doc.open("g", {{"class", "node"}});
  doc.title("node " + std::to_string(id) + (w.label.empty() ? "" : " (" + w.label + ")") + ": " +
            std::to_string(w.pixels) + " pixels, " + std::to_string(w.page_requests_served) +
            " page requests served");
  if (w.page_requests_served > 0) {
    const double ring = 1.0 + 0.35 * r * fraction(w.page_requests_served, s.max_requests);
    doc.leaf("circle", {{"cx", cx}, {"cy", cy}, {"r", num(r + ring / 2)}, {"fill", "none"}, {"stroke", "#1f6f8b"},
                        {"stroke-width", num(ring)}});
  }
  doc.leaf("circle", {{"cx", cx}, {"cy", cy}, {"r", num(r)}, {"fill", hex(fill)}, {"stroke", "#333333"}});
  const bool dark = 0.299 * fill.r + 0.587 * fill.g + 0.114 * fill.b < 110.0;
  doc.text(w.label.empty() ? std::to_string(id) : w.label,
           {{"x", cx}, {"y", num(std::stod(cy) + 0.32 * r)}, {"text-anchor", "middle"}, {"font-size", num(label_em * r)},
            {"fill", dark ? "white" : "black"}});
  doc.close();
}

// One line of the legend's notes, after a short sample of a link's stroke
// when it explains one.
struct Note {
  std::string text;
  const char* sample = nullptr;  // stroke colour of the sample; none: no sample
};

// What the picture shows beyond the colour bars, only what it has: rings if
// some node served pages, the rest if there are links.
std::vector<Note> legend_notes(const MachineDrawing& m, const Scales& s) {
  std::vector<Note> notes;
  if (s.max_requests > 0)
    notes.push_back({"ring width: page requests served (max " + std::to_string(s.max_requests) + ")"});
  if (m.links.empty()) return notes;
  notes.push_back({"each direction drawn on its right-hand side"});
  const auto idle = std::count_if(m.links.begin(), m.links.end(), [](const LinkTraffic& l) { return l.packets == 0; });
  if (m.links.size() > max_detailed_links && idle > 0)
    notes.push_back({std::to_string(idle) + " idle links not drawn"});
  else if (idle > 0)
    notes.push_back({"idle link: carried no packets", idle_grey});
  if (std::any_of(m.links.begin(), m.links.end(),
                  [&](const LinkTraffic& l) { return link_geometry(m, std::min(l.from, l.to), std::max(l.from, l.to)).wrap; }))
    notes.push_back({"stubs at the border: wrap-around links"});
  return notes;
}

constexpr double note_step = 16;

// Colour bars for node work and, with links, for traffic; then the notes.
void draw_legend(SvgDocument& doc, double y, const MachineDrawing& m, const Scales& s,
                 const std::vector<Note>& notes) {
  doc.open("g", {{"class", "legend"}});
  doc.open("defs", {});
  // Fixed ids with fixed content: duplicates across inlined SVGs are harmless.
  scale_gradient(doc, "viz-work-scale", work_scale);
  scale_gradient(doc, "viz-traffic-scale", traffic_scale);
  doc.close();
  colour_bar(doc, 20, y, "viz-work-scale", "node fill: pixels computed", static_cast<double>(s.max_pixels));
  if (!m.links.empty())
    colour_bar(doc, 220, y, "viz-traffic-scale", s.by_bytes ? "link: bytes carried" : "link: packets carried",
               static_cast<double>(s.max_link));
  for (std::size_t i = 0; i < notes.size(); ++i) {
    const double line_y = y + note_step * static_cast<double>(i);
    double x = 420;
    if (notes[i].sample) {
      doc.leaf("line", {{"x1", num(x)}, {"y1", num(line_y - 4)}, {"x2", num(x + 20)}, {"y2", num(line_y - 4)},
                        {"stroke", notes[i].sample}, {"stroke-width", "1.5"}});
      x += 26;
    }
    doc.text(notes[i].text, {{"x", num(x)}, {"y", num(line_y)}, {"font-size", "11"}});
  }
  doc.close();
}

}  // namespace

int machine_node_count(const MachineDrawing& m) {
  constexpr int max_nodes = 4096;
  const bool grid = m.kind == MachineKind::mesh || m.kind == MachineKind::torus;
  if (m.kind == MachineKind::hypercube) {
    if (m.dim_a < 0 || m.dim_a > 12)
      throw std::invalid_argument("machine drawing: hypercube dimension " + std::to_string(m.dim_a) + " not in 0..12");
    return 1 << m.dim_a;
  }
  const long long n = grid ? static_cast<long long>(m.dim_a) * m.dim_b : m.dim_a;
  if (m.dim_a < 1 || (grid && m.dim_b < 1) || n > max_nodes)
    throw std::invalid_argument("machine drawing: " + std::to_string(m.dim_a) +
                                (grid ? "x" + std::to_string(m.dim_b) : std::string{}) +
                                " is not a drawable size (1.." + std::to_string(max_nodes) + " nodes)");
  return static_cast<int>(n);
}

std::string machine_svg(const MachineDrawing& m) {
  const int n = machine_node_count(m);
  validate(m, n);
  const std::vector<Vec2> pos = layout(m, n);
  Vec2 lo = pos.front(), hi = pos.front();
  for (const Vec2& p : pos) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  const double bw = hi.x - lo.x + 2 * margin, bh = hi.y - lo.y + 2 * margin;
  View v;
  // As large as fits 720 x 600; larger, within max_extent, if labels would be too small.
  const double legible = min_label_px / (label_em * node_radius);
  v.scale = std::max(std::min({720.0 / bw, 600.0 / bh, 90.0}), std::min(legible, max_extent / std::max(bw, bh)));
  const double width = std::max(bw * v.scale, 700.0) + 20.0;
  const double title_h = m.title.empty() ? 10.0 : 34.0;
  v.origin = lo - Vec2{margin, margin};
  v.left = (width - bw * v.scale) / 2;
  v.top = title_h;
  const double legend_y = title_h + bh * v.scale + 16;
  const Scales s = scales_of(m);
  const std::vector<Note> notes = legend_notes(m, s);
  SvgDocument doc(width, legend_y + std::max(44.0, note_step * static_cast<double>(notes.size()) + 4));
  doc.leaf("rect", {{"width", "100%"}, {"height", "100%"}, {"fill", "white"}});
  if (!m.title.empty())
    doc.text(m.title, {{"x", num(width / 2)}, {"y", "22"}, {"text-anchor", "middle"}, {"font-size", "15"},
                       {"font-weight", "bold"}});
  draw_links(doc, m, pos, v, s);
  doc.open("g", {{"class", "nodes"}});
  for (int i = 0; i < n; ++i)
    draw_node(doc, i, m.nodes[static_cast<std::size_t>(i)], pos[static_cast<std::size_t>(i)], v, s);
  doc.close();
  draw_legend(doc, legend_y, m, s, notes);
  return doc.finish();
}

}  // namespace viz
