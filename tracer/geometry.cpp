// Single-precision intersection routines; see geometry.hpp for the contract.
#include "tracer/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

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

// Is vertex ring[k] an ear: convex, with no other remaining vertex inside?
bool is_ear(const std::vector<P2>& pts, const std::vector<std::uint32_t>& ring, std::size_t k,
            double sign) {
  const std::size_t n = ring.size();
  const P2& a = pts[ring[(k + n - 1) % n]];
  const P2& b = pts[ring[k]];
  const P2& c = pts[ring[(k + 1) % n]];
  if (sign * cross2(a, b, c) <= 0) return false;
  for (std::size_t j = 0; j < n; ++j) {
    if (j == k || j == (k + 1) % n || j == (k + n - 1) % n) continue;
    if (inside_triangle(pts[ring[j]], a, b, c, sign)) return false;
  }
  return true;
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

// Any ring: clip the first ear from the start of the ring, again and again;
// a ring with no ear left is finished as a fan. At least O(n^2).
void clip_first_ears(std::vector<std::uint32_t> ring, const std::vector<P2>& pts, double sign,
                     Triangles& tris) {
  while (ring.size() > 3) {
    std::size_t k = 0;
    while (k < ring.size() && !is_ear(pts, ring, k, sign)) ++k;
    if (k == ring.size()) break;  // no ear: finish as a fan below
    const std::size_t n_ring = ring.size();
    tris.push_back({ring[(k + n_ring - 1) % n_ring], ring[k], ring[(k + 1) % n_ring]});
    ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(k));
  }
  for (std::size_t k = 1; k + 1 < ring.size(); ++k) tris.push_back({ring[0], ring[k], ring[k + 1]});
}
}  // namespace

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(const std::vector<Vec3d>& v) {
  Triangles tris;
  if (v.size() < 3) return tris;
  // Project onto the plane that drops the normal's dominant axis.
  const Vec3d n = cross(v[1] - v[0], v[2] - v[0]);
  const Vec3d an{std::fabs(n.x), std::fabs(n.y), std::fabs(n.z)};
  const int drop = an.x > an.y ? (an.x > an.z ? 0 : 2) : (an.y > an.z ? 1 : 2);
  const int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
  std::vector<P2> pts;
  for (const Vec3d& p : v) pts.push_back({p[ax], p[ay]});
  const double sign = n[drop] >= 0 ? 1.0 : -1.0;  // winding as seen in the projection
  std::vector<std::uint32_t> ring(v.size());
  for (std::uint32_t i = 0; i < ring.size(); ++i) ring[i] = i;
  tris.reserve(v.size() - 2);
  if (is_strictly_convex(pts, sign))
    clip_alternate_ears(std::move(ring), tris);
  else
    clip_first_ears(std::move(ring), pts, sign, tris);
  return tris;
}

}  // namespace tracer
