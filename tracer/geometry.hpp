// Ray/primitive intersection in single precision: rays, boxes, triangles,
// spheres and cones (NFF's primitives once polygons are triangulated).
// Invariants: every routine is a pure function of its arguments (no state),
// so a hit distance depends only on the ray and the primitive's stored floats
// — never on the acceleration structure or the page layout that led there.
// A routine reports a hit only for t in the open interval (t_min, t_max).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "tracer/vec.hpp"

namespace tracer {

// v truncated toward zero and clamped to [lo, hi]; NaN gives lo. Casting a
// floating value that int cannot hold, or NaN, is undefined, so the clamp
// comes first (a scene near the limits of float can produce either).
template <typename F>
int clamped_int(F v, int lo, int hi) {
  if (!(v >= static_cast<F>(lo))) return lo;
  if (v >= static_cast<F>(hi)) return hi;
  return static_cast<int>(v);
}

struct Ray {
  Vec3f origin;
  Vec3f dir;  // not necessarily unit length
};

struct Box3f {
  Vec3f lo{1e30f, 1e30f, 1e30f};
  Vec3f hi{-1e30f, -1e30f, -1e30f};

  void extend(const Vec3f& p) { lo = min(lo, p); hi = max(hi, p); }
  void extend(const Box3f& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
  bool empty() const { return lo.x > hi.x; }
  Vec3f centre() const { return lo * 0.5f + hi * 0.5f; }  // the same as (lo + hi) / 2, but finite
  Vec3f extent() const { return hi - lo; }
  float half_area() const {
    const Vec3f d = extent();
    return empty() ? 0.0f : d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

// `b` widened on every side by `relative` times its largest coordinate
// magnitude (plus a denormal), a few float ulps: room for the rounding of
// the arithmetic that produced its corners or will test against it.
inline Box3f widened(Box3f b, float relative) {
  const float m = std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                            std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z)});
  const float pad = m * relative + 1e-30f;
  b.lo -= Vec3f{pad, pad, pad};
  b.hi += Vec3f{pad, pad, pad};
  return b;
}

// Reciprocal direction, precomputed once per ray for the slab tests.
struct RayInverse {
  Vec3f inv_dir;
  explicit RayInverse(const Ray& r)
      : inv_dir{1.0f / r.dir.x, 1.0f / r.dir.y, 1.0f / r.dir.z} {}
};

// Slab test: does the ray meet the box within [t_min, t_max]? If so t_entry
// is where. Inline: it is the innermost operation of traversal. The operand
// order of min/max drops a NaN (0 * inf on a slab face) for the running bound.
inline bool slab_test(const Ray& r, const RayInverse& inv, const Box3f& b, float t_min,
                      float t_max, float& t_entry) {
  auto lo = [](float a, float b) { return b < a ? b : a; };
  auto hi = [](float a, float b) { return a < b ? b : a; };
  const float x0 = (b.lo.x - r.origin.x) * inv.inv_dir.x, x1 = (b.hi.x - r.origin.x) * inv.inv_dir.x;
  const float y0 = (b.lo.y - r.origin.y) * inv.inv_dir.y, y1 = (b.hi.y - r.origin.y) * inv.inv_dir.y;
  const float z0 = (b.lo.z - r.origin.z) * inv.inv_dir.z, z1 = (b.hi.z - r.origin.z) * inv.inv_dir.z;
  t_entry = hi(hi(hi(t_min, lo(x0, x1)), lo(y0, y1)), lo(z0, z1));
  t_max = lo(lo(lo(t_max, hi(x0, x1)), hi(y0, y1)), hi(z0, z1));
  return t_entry <= t_max;
}

inline std::optional<float> intersect_box(const Ray& r, const RayInverse& inv, const Box3f& b,
                                          float t_min, float t_max) {
  float t;
  return slab_test(r, inv, b, t_min, t_max, t) ? std::optional<float>(t) : std::nullopt;
}

struct TriangleHit {
  float t, u, v;  // barycentric (u, v) of vertex 1 and 2
};

// Two-sided Moeller-Trumbore on a triangle stored as v0, e1 = v1 - v0, e2 = v2 - v0.
inline std::optional<TriangleHit> intersect_triangle(const Ray& r, const Vec3f& v0,
                                                     const Vec3f& e1, const Vec3f& e2,
                                                     float t_min, float t_max) {
  const Vec3f p = cross(r.dir, e2);
  const float det = dot(e1, p);
  if (det == 0.0f) return std::nullopt;  // ray parallel to the plane
  const float inv_det = 1.0f / det;
  const Vec3f s = r.origin - v0;
  const float u = dot(s, p) * inv_det;
  if (u < 0.0f || u > 1.0f) return std::nullopt;
  const Vec3f q = cross(s, e1);
  const float v = dot(r.dir, q) * inv_det;
  if (v < 0.0f || u + v > 1.0f) return std::nullopt;
  const float t = dot(e2, q) * inv_det;
  if (!(t > t_min && t < t_max)) return std::nullopt;
  return TriangleHit{t, u, v};
}

// Sphere; a negative radius means only the inside is visible: hits where the
// inward normal faces away from the ray are skipped.
std::optional<float> intersect_sphere(const Ray& r, const Vec3f& centre, float radius,
                                      float t_min, float t_max);
Vec3f sphere_normal(const Vec3f& centre, float radius, const Vec3f& p);

// Cone or cylinder between base and apex, no caps, radii linear along the axis.
// Negative radii: only the inside is visible (as for spheres).
struct ConeShape {
  Vec3f base;
  Vec3f apex;
  float base_radius;
  float apex_radius;
};
std::optional<float> intersect_cone(const Ray& r, const ConeShape& c, float t_min, float t_max);
Vec3f cone_normal(const ConeShape& c, const Vec3f& p);  // unit, outward (inward if radii < 0)
Box3f cone_bounds(const ConeShape& c);

// Ear clipping of a planar polygon of any vertex count, convex or not, in the
// plane fixed by its first three vertices; returns vertex index triples with
// the polygon's winding. A strictly convex polygon has its ears clipped at
// every other vertex, pass after pass, in O(n): no long slivers, whose hit
// distances single precision cannot resolve. Any other polygon has its ears
// clipped on a walk round it, each ear tested against the vertices near it;
// one that has no ear left (self-intersecting or degenerate) is finished as
// a fan. Every input gives n - 2 triangles.
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3d> vertices);

}  // namespace tracer
