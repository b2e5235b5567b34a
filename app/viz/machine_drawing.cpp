// Machine drawing: layout in "units" (neighbouring nodes about one unit
// apart), one affine map to pixels, then one drawing on cairo for every
// surface. See machine_drawing.hpp for the layouts.
#include "app/viz/machine_drawing.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "app/viz/drawing.hpp"
#include "app/viz/legend.hpp"

namespace viz {
namespace {

using detail::set_colour;

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
constexpr Rgb8 idle_grey{204, 204, 204};

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
  Vec2 px(Vec2 p) const { return {left + (p.x - origin.x) * scale, top + (p.y - origin.y) * scale}; }
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

bool is_wrap(const MachineDrawing& m, const LinkTraffic& l) {
  return link_geometry(m, std::min(l.from, l.to), std::max(l.from, l.to)).wrap;
}

// Outward direction of a torus wrap link at node p (towards the border it leaves by).
Vec2 wrap_outward(Vec2 p, Vec2 other) {
  if (p.y == other.y) return {p.x < other.x ? -1.0 : 1.0, 0.0};
  return {0.0, p.y < other.y ? -1.0 : 1.0};
}

void line(cairo_t* cr, const View& v, Vec2 p, Vec2 q) {
  const Vec2 a = v.px(p), b = v.px(q);
  cairo_move_to(cr, a.x, a.y);
  cairo_line_to(cr, b.x, b.y);
}

// A quadratic Bezier from p through control c to q, as the cubic cairo draws.
void curve(cairo_t* cr, const View& v, Vec2 p, Vec2 c, Vec2 q) {
  const Vec2 a = v.px(p), k = v.px(c), b = v.px(q);
  const Vec2 c1 = a + (k - a) * (2.0 / 3.0), c2 = b + (k - b) * (2.0 / 3.0);
  cairo_move_to(cr, a.x, a.y);
  cairo_curve_to(cr, c1.x, c1.y, c2.x, c2.y, b.x, b.y);
}

// Adds the link's stroke(s) to the current path.
void link_path(cairo_t* cr, const MachineDrawing& m, const std::vector<Vec2>& pos, const LinkTraffic& l, const View& v,
               double lane) {
  const int a = std::min(l.from, l.to), b = std::max(l.from, l.to);
  const Vec2 pa = pos[static_cast<std::size_t>(a)], pb = pos[static_cast<std::size_t>(b)];
  const Vec2 d = pb - pa;
  const double len = std::hypot(d.x, d.y);
  const Vec2 n{-d.y / len, d.x / len};
  // Right-hand lane of the direction of travel keeps the two directions apart.
  const Vec2 off = n * (l.from == a ? lane : -lane);
  const LinkGeometry g = link_geometry(m, a, b);
  if (!g.wrap && g.bow == 0) return line(cr, v, pa + off, pb + off);
  if (!g.wrap) return curve(cr, v, pa + off, (pa + pb) * 0.5 + n * g.bow + off, pb + off);
  for (const auto& [p, q] : {std::pair{pa, pb}, std::pair{pb, pa}}) {
    const Vec2 o = wrap_outward(p, q);
    curve(cr, v, p + off, p + o * 0.5 + off, p + o * 0.65 + n * 0.3 + off);
  }
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

// One line of the legend's notes, after a short sample of a link's stroke
// when it explains one.
struct Note {
  std::string text;
  bool idle_sample = false;  // drawn after a sample of an idle link
};

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
    notes.push_back({"idle link: carried no packets", true});
  if (std::any_of(m.links.begin(), m.links.end(), [&](const LinkTraffic& l) { return is_wrap(m, l); }))
    notes.push_back({"stubs at the border: wrap-around links"});
  return notes;
}

constexpr double note_step = 16;

// Everything the picture needs, placed: decided before any surface exists,
// so that every surface gets the same size.
struct Layout {
  std::vector<Vec2> pos;  // layout units
  View view;
  Scales scales;
  std::vector<Note> notes;
  double width = 0, height = 0, legend_y = 0;
};

Layout layout_of(const MachineDrawing& m) {
  const int n = machine_node_count(m);
  validate(m, n);
  Layout out;
  out.pos = layout(m, n);
  Vec2 lo = out.pos.front(), hi = out.pos.front();
  for (const Vec2& p : out.pos) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  const double bw = hi.x - lo.x + 2 * margin, bh = hi.y - lo.y + 2 * margin;
  View& v = out.view;
  // As large as fits 720 x 600; larger, within max_extent, if labels would be too small.
  const double legible = min_label_px / (label_em * node_radius);
  v.scale = std::max(std::min({720.0 / bw, 600.0 / bh, 90.0}), std::min(legible, max_extent / std::max(bw, bh)));
  out.width = std::max(bw * v.scale, 700.0) + 20.0;
  const double title_h = m.title.empty() ? 10.0 : 34.0;
  v.origin = lo - Vec2{margin, margin};
  v.left = (out.width - bw * v.scale) / 2;
  v.top = title_h;
  out.legend_y = title_h + bh * v.scale + 16;
  out.scales = scales_of(m);
  out.notes = legend_notes(m, out.scales);
  out.height = out.legend_y + std::max(44.0, note_step * static_cast<double>(out.notes.size()) + 4);
  return out;
}

void draw_links(cairo_t* cr, const MachineDrawing& m, const Layout& lay) {
  const bool complete = m.kind == MachineKind::complete;
  const double lane = complete ? 0.03 : 0.07;
  const double max_width = complete ? 2.5 : std::max(1.5, 0.1 * lay.view.scale);
  const Scales& s = lay.scales;
  auto width = [&](double f) { return 0.8 + (max_width - 0.8) * f; };
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  if (m.links.size() > max_detailed_links) {
    // Too many to tell apart: one stroke per traffic band, lightest first, idle links left out.
    std::vector<std::vector<const LinkTraffic*>> bands(traffic_bands);
    for (const LinkTraffic& l : m.links) {
      if (l.packets == 0) continue;
      const int band =
          std::min(traffic_bands - 1, static_cast<int>(fraction(s.measure(l), s.max_link) * traffic_bands));
      bands[static_cast<std::size_t>(band)].push_back(&l);
    }
    for (int b = 0; b < traffic_bands; ++b) {
      if (bands[static_cast<std::size_t>(b)].empty()) continue;
      const double f = (b + 0.5) / traffic_bands;
      for (const LinkTraffic* l : bands[static_cast<std::size_t>(b)]) link_path(cr, m, lay.pos, *l, lay.view, lane);
      set_colour(cr, traffic_scale(f));
      cairo_set_line_width(cr, width(f));
      cairo_stroke(cr);
    }
    cairo_restore(cr);
    return;
  }
  std::vector<const LinkTraffic*> active;
  set_colour(cr, idle_grey);
  cairo_set_line_width(cr, 0.8);
  for (const LinkTraffic& l : m.links) {
    if (l.packets > 0) {
      active.push_back(&l);
      continue;
    }
    link_path(cr, m, lay.pos, l, lay.view, 0.0);
    cairo_stroke(cr);
  }
  // Heaviest links last, so they are drawn on top.
  std::stable_sort(active.begin(), active.end(),
                   [&](const LinkTraffic* x, const LinkTraffic* y) { return s.measure(*x) < s.measure(*y); });
  for (const LinkTraffic* l : active) {
    const double f = fraction(s.measure(*l), s.max_link);
    link_path(cr, m, lay.pos, *l, lay.view, lane);
    set_colour(cr, traffic_scale(f));
    cairo_set_line_width(cr, width(f));
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

NodePlace place_of(Vec2 centre, const View& v) {
  const Vec2 c = v.px(centre);
  const double r = node_radius * v.scale;
  return {c.x, c.y, r, label_em * r};
}

void draw_node(cairo_t* cr, int id, const NodeWork& w, const NodePlace& p, const Scales& s) {
  const Rgb8 fill = work_scale(fraction(w.pixels, s.max_pixels));
  if (w.page_requests_served > 0) {
    const double ring = 1.0 + 0.35 * p.radius * fraction(w.page_requests_served, s.max_requests);
    cairo_arc(cr, p.x, p.y, p.radius + ring / 2, 0, 2 * std::numbers::pi);
    set_colour(cr, {31, 111, 139});
    cairo_set_line_width(cr, ring);
    cairo_stroke(cr);
  }
  cairo_arc(cr, p.x, p.y, p.radius, 0, 2 * std::numbers::pi);
  set_colour(cr, fill);
  cairo_fill_preserve(cr);
  set_colour(cr, {51, 51, 51});
  cairo_set_line_width(cr, 1);
  cairo_stroke(cr);
  const bool dark = 0.299 * fill.r + 0.587 * fill.g + 0.114 * fill.b < 110.0;
  set_colour(cr, dark ? Rgb8{255, 255, 255} : Rgb8{0, 0, 0});
  detail::show_text(cr, p.x, p.y + 0.32 * p.radius, w.label.empty() ? std::to_string(id) : w.label, {p.label_size},
                    detail::Align::centre);
}

// Colour bars for node work and, with links, for traffic; then the notes.
void draw_legend(cairo_t* cr, const MachineDrawing& m, const Layout& lay) {
  const double y = lay.legend_y;
  const Scales& s = lay.scales;
  detail::colour_bar(cr, 20, y, work_scale, "node fill: pixels computed", static_cast<double>(s.max_pixels));
  if (!m.links.empty())
    detail::colour_bar(cr, 220, y, traffic_scale, s.by_bytes ? "link: bytes carried" : "link: packets carried",
                       static_cast<double>(s.max_link));
  for (std::size_t i = 0; i < lay.notes.size(); ++i) {
    const double line_y = y + note_step * static_cast<double>(i);
    double x = 420;
    if (lay.notes[i].idle_sample) {
      set_colour(cr, idle_grey);
      cairo_set_line_width(cr, 1.5);
      cairo_move_to(cr, x, line_y - 4);
      cairo_line_to(cr, x + 20, line_y - 4);
      cairo_stroke(cr);
      x += 26;
    }
    set_colour(cr, {0, 0, 0});
    detail::show_text(cr, x, line_y, lay.notes[i].text, {11});
  }
}

void draw_machine(cairo_t* cr, const MachineDrawing& m, const Layout& lay) {
  if (!m.title.empty()) {
    set_colour(cr, {0, 0, 0});
    const auto [text, font] = detail::fit_text(m.title, {15, true}, 11, lay.width - 16);
    detail::show_text(cr, lay.width / 2, 22, text, font, detail::Align::centre);
  }
  draw_links(cr, m, lay);
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    draw_node(cr, static_cast<int>(i), m.nodes[i], place_of(lay.pos[i], lay.view), lay.scales);
  draw_legend(cr, m, lay);
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
  const Layout lay = layout_of(m);
  return detail::draw_svg("machine SVG", lay.width, lay.height, [&](cairo_t* cr) { draw_machine(cr, m, lay); });
}

std::string machine_pdf(const MachineDrawing& m) {
  const Layout lay = layout_of(m);
  return detail::draw_pdf("machine PDF", lay.width, lay.height, [&](cairo_t* cr) { draw_machine(cr, m, lay); });
}

tracer::Image machine_image(const MachineDrawing& m) {
  const Layout lay = layout_of(m);
  return detail::draw_image("machine image", static_cast<int>(std::ceil(lay.width)),
                            static_cast<int>(std::ceil(lay.height)), [&](cairo_t* cr) { draw_machine(cr, m, lay); });
}

std::vector<NodePlace> machine_node_places(const MachineDrawing& m) {
  const Layout lay = layout_of(m);
  std::vector<NodePlace> places;
  for (const Vec2& p : lay.pos) places.push_back(place_of(p, lay.view));
  return places;
}

std::vector<std::string> machine_legend_notes(const MachineDrawing& m) {
  std::vector<std::string> out;
  for (const Note& n : layout_of(m).notes) out.push_back(n.text);
  return out;
}

}  // namespace viz
