// Single-precision intersection routines; see geometry.hpp for the contract.
#include "tracer/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace tracer {

// Keeps the nearer root in (t_min, t_max) whose outward normal passes `visible`.
template <class Visible>
static std::optional<float> pick_root(float t0, float t1, float t_min, float t_max,
                                      Visible visible) {
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > t_min && t0 < t_max && visible(t0)) return t0;
  if (t1 > t_min && t1 < t_max && visible(t1)) return t1;
  return std::nullopt;
}

std::optional<float> intersect_sphere(const Ray& r, const Vec3f& centre, float radius,
                                      float t_min, float t_max) {
  const Vec3f oc = r.origin - centre;
  const float a = dot(r.dir, r.dir);
  const float b = dot(oc, r.dir);
  const float c = dot(oc, oc) - radius * radius;
  // Discriminant from the closest approach, which loses less precision than b^2 - ac.
  const Vec3f f = oc - r.dir * (b / a);
  const float disc = a * (radius * radius - dot(f, f));
  if (disc < 0.0f) return std::nullopt;
  const float q = -b - std::copysign(std::sqrt(disc), b);
  const float t0 = q != 0.0f ? c / q : 0.0f;
  const float t1 = q / a;
  if (radius > 0.0f)
    return pick_root(t0, t1, t_min, t_max, [](float) { return true; });
  // Inside visible: the outward normal must point along the ray.
  return pick_root(t0, t1, t_min, t_max, [&](float t) {
    return dot(r.origin + r.dir * t - centre, r.dir) > 0.0f;
  });
}

Vec3f sphere_normal(const Vec3f& centre, float radius, const Vec3f& p) {
  return (p - centre) * (1.0f / radius);
}

namespace {
struct ConeFrame {
  Vec3f w;       // unit axis, base to apex
  float height;  // base to apex distance
  float rb;      // |base radius|
  float slope;   // radius change per unit of height
};

ConeFrame cone_frame(const ConeShape& c) {
  const Vec3f axis = c.apex - c.base;
  const float h = length(axis);
  const float rb = std::fabs(c.base_radius);
  return {axis * (1.0f / h), h, rb, (std::fabs(c.apex_radius) - rb) / h};
}
}  // namespace

std::optional<float> intersect_cone(const Ray& r, const ConeShape& c, float t_min,
                                    float t_max) {
  const ConeFrame f = cone_frame(c);
  const Vec3f o = r.origin - c.base;
  const float ds = dot(r.dir, f.w), os = dot(o, f.w);
  const Vec3f dp = r.dir - f.w * ds, op = o - f.w * os;
  const float r0 = f.rb + f.slope * os;  // radius at the origin's axial position
  // |op + t dp|^2 = (r0 + slope ds t)^2, a quadratic a t^2 + 2 b t + c = 0.
  const float a = dot(dp, dp) - f.slope * f.slope * ds * ds;
  const float b = dot(op, dp) - f.slope * ds * r0;
  const float cc = dot(op, op) - r0 * r0;
  float t0, t1;
  if (std::fabs(a) < 1e-12f) {
    if (b == 0.0f) return std::nullopt;
    t0 = t1 = -cc / (2.0f * b);
  } else {
    const float disc = b * b - a * cc;
    if (disc < 0.0f) return std::nullopt;
    const float q = -b - std::copysign(std::sqrt(disc), b);
    t0 = q / a;
    t1 = q != 0.0f ? cc / q : t0;
  }
  const bool inside_only = c.base_radius < 0.0f || c.apex_radius < 0.0f;
  return pick_root(t0, t1, t_min, t_max, [&](float t) {
    const float s = os + ds * t;
    if (s < 0.0f || s > f.height || f.rb + f.slope * s < 0.0f) return false;
    return !inside_only || dot(cone_normal(c, r.origin + r.dir * t), r.dir) < 0.0f;
  });
}

Vec3f cone_normal(const ConeShape& c, const Vec3f& p) {
  const ConeFrame f = cone_frame(c);
  const Vec3f q = p - c.base;
  const Vec3f radial = normalize(q - f.w * dot(q, f.w));
  const Vec3f n = normalize(radial - f.w * f.slope);
  // For inside-only cones the normal points inward, toward the visible side.
  return (c.base_radius < 0.0f || c.apex_radius < 0.0f) ? -n : n;
}

Box3f cone_bounds(const ConeShape& c) {
  // Each end disc lies within a sphere of its radius; exact enough for culling.
  Box3f b;
  const float rb = std::fabs(c.base_radius), ra = std::fabs(c.apex_radius);
  b.extend(c.base - Vec3f{rb, rb, rb});
  b.extend(c.base + Vec3f{rb, rb, rb});
  b.extend(c.apex - Vec3f{ra, ra, ra});
  b.extend(c.apex + Vec3f{ra, ra, ra});
  return b;
}

namespace {
struct P2 {
  double x, y;
};
double cross2(const P2& a, const P2& b, const P2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}
bool inside_triangle(const P2& p, const P2& a, const P2& b, const P2& c, double sign) {
  return sign * cross2(a, b, p) >= 0 && sign * cross2(b, c, p) >= 0 && sign * cross2(c, a, p) >= 0;
}

// Does the ring turn with `sign` at every corner, going round exactly once?
// Then it is strictly convex: every corner is an ear.
bool is_strictly_convex(const std::vector<P2>& pts, double sign) {
  const std::size_t n = pts.size();
  double turning = 0;  // sum of exterior angles: 2 pi for a ring that goes round once
  for (std::size_t k = 0; k < n; ++k) {
    const P2& a = pts[(k + n - 1) % n];
    const P2& b = pts[k];
    const P2& c = pts[(k + 1) % n];
    const double turn = sign * cross2(a, b, c);
    if (!(turn > 0)) return false;
    const double along = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
    turning += std::atan2(turn, along);
  }
  return turning < 3 * std::numbers::pi;  // the sum is a multiple of 2 pi
}

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

// Strictly convex ring: each pass clips the ears at every other vertex, from
// ring position 0, and leaves the rest as the next, half-size ring; the last
// three vertices make the last triangle. O(n), and the triangles of a regular
// polygon are as fat as its ring allows: thin ones only along the rim, where
// they are small, instead of a fan's slivers across the whole polygon.
void clip_alternate_ears(std::vector<std::uint32_t> ring, Triangles& tris) {
  std::vector<std::uint32_t> kept;
  while (ring.size() > 3) {
    const std::size_t n = ring.size();
    kept.clear();
    for (std::size_t k = 0; k < n; ++k) {
      if (k % 2 == 0 && k + 1 < n)
        tris.push_back({ring[(k + n - 1) % n], ring[k], ring[k + 1]});
      else
        kept.push_back(ring[k]);
    }
    ring.swap(kept);
  }
  if (ring.size() == 3) tris.push_back({ring[0], ring[1], ring[2]});
}

// The remaining vertices of a ring in a uniform grid over its bounding box,
// of cells about as wide as high and about one vertex to a cell, so that a
// triangle finds the vertices it might hold by looking only at the cells its
// bounding box covers. A clipped vertex stays in its cell, marked removed.
class VertexGrid {
 public:
  explicit VertexGrid(const std::vector<P2>& pts) : pts_(pts), removed_(pts.size(), false) {
    lo_ = hi_ = pts.front();
    for (const P2& p : pts) {
      lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y)};
      hi_ = {std::max(hi_.x, p.x), std::max(hi_.y, p.y)};
    }
    const double n = static_cast<double>(pts.size());
    const double w = hi_.x - lo_.x, h = hi_.y - lo_.y;
    const double across = w > 0 && h > 0 ? std::sqrt(n * w / h) : w > 0 ? n : 1;
    // Not NaN (from coordinates so large that their differences overflow).
    columns_ = across >= 1 ? static_cast<std::size_t>(std::min(std::round(across), n)) : 1;
    rows_ = static_cast<std::size_t>(std::clamp(std::round(n / static_cast<double>(columns_)), 1.0, n));
    first_.assign(columns_ * rows_ + 1, 0);
    for (const P2& p : pts) ++first_[cell(p) + 1];
    for (std::size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
    items_.resize(pts.size());
    std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
    for (std::uint32_t i = 0; i < pts.size(); ++i) items_[fill[cell(pts[i])]++] = i;
  }

  void remove(std::uint32_t i) { removed_[i] = true; }

  // Does a remaining vertex other than a, b and c lie in triangle abc
  // (boundary included)?
  bool holds_another(std::uint32_t a, std::uint32_t b, std::uint32_t c, double sign) const {
    const P2 &pa = pts_[a], &pb = pts_[b], &pc = pts_[c];
    const std::size_t x0 = column(std::min({pa.x, pb.x, pc.x})), x1 = column(std::max({pa.x, pb.x, pc.x}));
    const std::size_t y0 = row(std::min({pa.y, pb.y, pc.y})), y1 = row(std::max({pa.y, pb.y, pc.y}));
    for (std::size_t y = y0; y <= y1; ++y)
      for (std::uint32_t k = first_[y * columns_ + x0]; k < first_[y * columns_ + x1 + 1]; ++k) {
        const std::uint32_t j = items_[k];
        if (j == a || j == b || j == c || removed_[j]) continue;
        if (inside_triangle(pts_[j], pa, pb, pc, sign)) return true;
      }
    return false;
  }

 private:
  static std::size_t along(double v, double lo, double hi, std::size_t cells) {
    if (!(hi > lo)) return 0;
    const double t = (v - lo) / (hi - lo) * static_cast<double>(cells);
    return static_cast<std::size_t>(clamped_int(t, 0, static_cast<int>(cells - 1)));
  }
  std::size_t column(double x) const { return along(x, lo_.x, hi_.x, columns_); }
  std::size_t row(double y) const { return along(y, lo_.y, hi_.y, rows_); }
  std::size_t cell(const P2& p) const { return row(p.y) * columns_ + column(p.x); }

  const std::vector<P2>& pts_;
  std::vector<bool> removed_;
  P2 lo_{}, hi_{};
  std::size_t columns_ = 1, rows_ = 1;
  std::vector<std::uint32_t> first_;  // cell c holds items_[first_[c] .. first_[c + 1]), cells row by row
  std::vector<std::uint32_t> items_;
};

// Any ring: walk round it clipping ears. A vertex is an ear when its corner
// turns with `sign` and no other remaining vertex lies in its triangle.
// After a clip the walk passes over the next vertex, as clip_alternate_ears
// does, so that where the ring is convex the ears are fat rather than a fan
// of slivers round one vertex. A whole turn of the remaining ring with no
// ear (a self-crossing or degenerate ring) finishes it as a fan. Near O(n)
// on the polygons one meets: an ear's test looks only at the grid cells
// round its triangle.
void clip_ears(const std::vector<P2>& pts, double sign, Triangles& tris) {
  const auto n = static_cast<std::uint32_t>(pts.size());
  std::vector<std::uint32_t> prev(n), next(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  VertexGrid grid(pts);
  std::uint32_t remaining = n, at = 0, since_clip = 0;
  while (remaining > 3 && since_clip < remaining) {
    const std::uint32_t a = prev[at], c = next[at];
    const bool ear = sign * cross2(pts[a], pts[at], pts[c]) > 0 && !grid.holds_another(a, at, c, sign);
    if (!ear) {
      at = c;
      ++since_clip;
      continue;
    }
    tris.push_back({a, at, c});
    next[a] = c;
    prev[c] = a;
    grid.remove(at);
    --remaining;
    at = next[c];
    since_clip = 0;
  }
  for (std::uint32_t v = next[at]; next[v] != at; v = next[v]) tris.push_back({at, v, next[v]});
}
}  // namespace

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3d> v) {
  Triangles tris;
  if (v.size() < 3) return tris;
  // Project onto the plane that drops the normal's dominant axis.
  const Vec3d n = cross(v[1] - v[0], v[2] - v[0]);
  const Vec3d an{std::fabs(n.x), std::fabs(n.y), std::fabs(n.z)};
  const int drop = an.x > an.y ? (an.x > an.z ? 0 : 2) : (an.y > an.z ? 1 : 2);
  const int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
  const double sign = n[drop] >= 0 ? 1.0 : -1.0;  // winding as seen in the projection
  if (v.size() == 3) {
    // A triangle turning with `sign` at all three corners goes round once
    // (its exterior angles add up to 2 pi), so it is strictly convex and
    // the convex path would give it whole; the rest go the general way.
    const P2 a{v[0][ax], v[0][ay]}, b{v[1][ax], v[1][ay]}, c{v[2][ax], v[2][ay]};
    if (sign * cross2(c, a, b) > 0 && sign * cross2(a, b, c) > 0 && sign * cross2(b, c, a) > 0) {
      tris.push_back({0, 1, 2});
      return tris;
    }
  }
  std::vector<P2> pts;
  for (const Vec3d& p : v) pts.push_back({p[ax], p[ay]});
  tris.reserve(v.size() - 2);
  if (is_strictly_convex(pts, sign)) {
    std::vector<std::uint32_t> ring(v.size());
    for (std::uint32_t i = 0; i < ring.size(); ++i) ring[i] = i;
    clip_alternate_ears(std::move(ring), tris);
  } else {
    clip_ears(pts, sign, tris);
  }
  return tris;
}

}  // namespace tracer
