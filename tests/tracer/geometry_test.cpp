// Intersection routines against analytic answers.
#include "tracer/geometry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>
#include <cmath>
#include <numbers>

namespace tracer {
namespace {

constexpr float kInf = 1e30f;

TEST(ClampedInt, TruncatesInRangeAndClampsWhatIntCannotHold) {
  EXPECT_EQ(clamped_int(2.9f, 0, 7), 2);
  EXPECT_EQ(clamped_int(7.5f, 0, 7), 7);
  EXPECT_EQ(clamped_int(-0.5f, 0, 7), 0);
  EXPECT_EQ(clamped_int(0.5, 1, 7), 1);
  EXPECT_EQ(clamped_int(3e38f, 0, 7), 7);
  EXPECT_EQ(clamped_int(-3e38f, 0, 7), 0);
  EXPECT_EQ(clamped_int(std::numeric_limits<float>::infinity(), 0, 7), 7);
  EXPECT_EQ(clamped_int(std::numeric_limits<float>::quiet_NaN(), 0, 7), 0);
  EXPECT_EQ(clamped_int(std::numeric_limits<double>::quiet_NaN(), 1, 7), 1);
}

TEST(Sphere, HitsNearSideFromOutside) {
  const auto t = intersect_sphere({{0, 0, -5}, {0, 0, 1}}, {0, 0, 0}, 1.0f, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 4.0f, 1e-5f);
}

TEST(Sphere, HitsFarSideFromInside) {
  const auto t = intersect_sphere({{0, 0, 0}, {0, 0, 2}}, {0, 0, 0}, 1.0f, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.5f, 1e-6f);
}

TEST(Sphere, MissesWhenRayPassesBeside) {
  EXPECT_FALSE(intersect_sphere({{0, 1.01f, -5}, {0, 0, 1}}, {0, 0, 0}, 1.0f, 0.0f, kInf));
}

TEST(Sphere, NegativeRadiusShowsOnlyTheInside) {
  // From outside, the near side faces away (inward normal): the far side is seen.
  const auto t = intersect_sphere({{0, 0, -5}, {0, 0, 1}}, {0, 0, 0}, -1.0f, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 6.0f, 1e-5f);
  const Vec3f n = sphere_normal({0, 0, 0}, -1.0f, {0, 0, 1});
  EXPECT_FLOAT_EQ(n.z, -1.0f);  // points inward, toward the visible side
}

TEST(Sphere, RespectsTheInterval) {
  EXPECT_FALSE(intersect_sphere({{0, 0, -5}, {0, 0, 1}}, {0, 0, 0}, 1.0f, 0.0f, 3.9f));
}

TEST(Triangle, HitGivesDistanceAndBarycentrics) {
  const auto h = intersect_triangle({{0.25f, 0.25f, 1}, {0, 0, -1}}, {0, 0, 0}, {1, 0, 0},
                                    {0, 1, 0}, 0.0f, kInf);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, 1.0f, 1e-6f);
  EXPECT_NEAR(h->u, 0.25f, 1e-6f);
  EXPECT_NEAR(h->v, 0.25f, 1e-6f);
}

TEST(Triangle, IsTwoSidedAndMissesOutside) {
  EXPECT_TRUE(intersect_triangle({{0.2f, 0.2f, -1}, {0, 0, 1}}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0},
                                 0.0f, kInf));
  EXPECT_FALSE(intersect_triangle({{0.6f, 0.6f, 1}, {0, 0, -1}}, {0, 0, 0}, {1, 0, 0},
                                  {0, 1, 0}, 0.0f, kInf));
}

TEST(Cylinder, HitsSideAtRadius) {
  const ConeShape c{{0, 0, 0}, {0, 0, 2}, 1.0f, 1.0f};
  const auto t = intersect_cone({{-5, 0, 1}, {1, 0, 0}}, c, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 4.0f, 1e-5f);
  const Vec3f n = cone_normal(c, {-1, 0, 1});
  EXPECT_NEAR(n.x, -1.0f, 1e-6f);
  EXPECT_NEAR(n.z, 0.0f, 1e-6f);
}

TEST(Cylinder, HasNoCaps) {
  const ConeShape c{{0, 0, 0}, {0, 0, 2}, 1.0f, 1.0f};
  EXPECT_FALSE(intersect_cone({{0, 0, -5}, {0, 0, 1}}, c, 0.0f, kInf));  // along the axis
  EXPECT_FALSE(intersect_cone({{-5, 0, 3}, {1, 0, 0}}, c, 0.0f, kInf));  // beyond the apex
}

TEST(Cone, HitsWhereRadiusShrinks) {
  // Radius 1 at z = 0 down to 0 at z = 2: at z = 1 the radius is 0.5.
  const ConeShape c{{0, 0, 0}, {0, 0, 2}, 1.0f, 0.0f};
  const auto t = intersect_cone({{-5, 0, 1}, {1, 0, 0}}, c, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 4.5f, 1e-5f);
  const Vec3f n = cone_normal(c, {-0.5f, 0, 1});
  // Slope 1/2: the outward normal tilts up along the axis by atan(1/2).
  EXPECT_NEAR(n.z / -n.x, 0.5f, 1e-5f);
}

TEST(Cone, NegativeRadiusShowsOnlyTheInside) {
  const ConeShape c{{0, 0, 0}, {0, 0, 2}, -1.0f, -1.0f};
  const auto t = intersect_cone({{-5, 0, 1}, {1, 0, 0}}, c, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 6.0f, 1e-5f);
}

TEST(Box, SlabTestGivesEntryDistance) {
  const Ray r{{-3, 0.5f, 0.5f}, {1, 0, 0}};
  const Box3f b{{0, 0, 0}, {1, 1, 1}};
  const auto t = intersect_box(r, RayInverse(r), b, 0.0f, kInf);
  ASSERT_TRUE(t);
  EXPECT_FLOAT_EQ(*t, 3.0f);
  EXPECT_FALSE(intersect_box(r, RayInverse(r), b, 0.0f, 2.0f));
}

double shoelace_area(const std::vector<Vec3d>& v) {
  double twice = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec3d& a = v[i];
    const Vec3d& b = v[(i + 1) % v.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * twice;
}

bool inside_polygon(const std::vector<Vec3d>& v, double x, double y) {
  bool in = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
    if ((v[i].y > y) != (v[j].y > y) && x < (v[j].x - v[i].x) * (y - v[i].y) / (v[j].y - v[i].y) + v[i].x) in = !in;
  return in;
}

double smallest_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  auto angle = [](const Vec3d& p, const Vec3d& q, const Vec3d& r) {
    return std::acos(dot(normalize(q - p), normalize(r - p)));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// n - 2 triangles, each turning with the polygon, their areas summing to
// the polygon's, and sample points inside it each in exactly one triangle,
// outside it in none. Returns the share of the area in triangles with a
// corner under one degree.
double check_triangulation(const std::vector<Vec3d>& v, double extent, double step) {
  const auto tris = triangulate_polygon(v);
  EXPECT_EQ(tris.size(), v.size() - 2);
  double area = 0, thin_area = 0;
  for (const auto& t : tris) {
    const double a = 0.5 * cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]).z;
    EXPECT_GT(a, 0) << "every triangle keeps the polygon's winding";
    area += a;
    if (smallest_angle(v[t[0]], v[t[1]], v[t[2]]) < std::numbers::pi / 180) thin_area += a;
  }
  const double polygon_area = shoelace_area(v);
  EXPECT_NEAR(area, polygon_area, 1e-9 * polygon_area);
  auto in_triangle = [&](const std::array<std::uint32_t, 3>& t, double x, double y) {
    for (int k = 0; k < 3; ++k) {
      const Vec3d& a = v[t[k]];
      const Vec3d& b = v[t[(k + 1) % 3]];
      if ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x) < 0) return false;
    }
    return true;
  };
  // Offsets keep the samples off the vertices and the diagonals.
  for (double y = -extent + 0.00731; y < extent; y += step)
    for (double x = -extent + 0.00517; x < extent; x += step * 1.013) {
      int covering = 0;
      for (const auto& t : tris) covering += in_triangle(t, x, y);
      EXPECT_EQ(covering, inside_polygon(v, x, y) ? 1 : 0) << "point " << x << ' ' << y;
    }
  return thin_area / area;
}

// An L shape (area 3), counter-clockwise, first corner convex.
TEST(Triangulate, NonConvexPolygonCoversItsArea) {
  const std::vector<Vec3d> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  ASSERT_NEAR(shoelace_area(l), 3.0, 1e-12);
  check_triangulation(l, 2.0, 0.0917);
}

std::vector<Vec3d> regular_polygon(int vertices, double radius) {
  std::vector<Vec3d> v;
  for (int i = 0; i < vertices; ++i) {
    const double a = 2 * std::numbers::pi * i / vertices;
    v.push_back({radius * std::cos(a), radius * std::sin(a), 0});
  }
  return v;
}

// No triangulation on a regular polygon's own vertices avoids thin triangles
// (an ear's corners are pi / n), but a fan makes every triangle a sliver; here
// the thin ones must be small. Counter-clockwise, odd and even counts.
TEST(Triangulate, RegularPolygonHasFewThinTriangles) {
  for (int n : {1999, 2000})
    EXPECT_LT(check_triangulation(regular_polygon(n, 1.5), 1.5, 0.0731), 0.01)
        << n << ": share of the area in triangles with a corner under 1 degree";
}

TEST(Triangulate, ConvexPolygonIsCoveredOnce) {
  for (int n : {5, 6, 7, 64, 101}) check_triangulation(regular_polygon(n, 1.0), 1.0, 0.0517);
}

// A star of `points` spikes (radii 1 and 0.6), counter-clockwise, starting
// at a convex corner as NFF requires: half its corners are reflex.
std::vector<Vec3d> star(int points) {
  std::vector<Vec3d> v;
  for (int k = 0; k < 2 * points; ++k) {
    const int i = (k + 2 * points - 1) % (2 * points);
    const double r = i % 2 == 0 ? 1.0 : 0.6;
    const double a = std::numbers::pi * i / points;
    v.push_back({r * std::cos(a), r * std::sin(a), 0});
  }
  return v;
}

// An arm of `turns` turns and width 0.6 winding out from the centre and back,
// counter-clockwise, starting at a convex corner: n vertices, most of whose
// ears hold other vertices.
std::vector<Vec3d> spiral(int n, double turns) {
  std::vector<Vec3d> v, back;
  const int m = n / 2;
  for (int i = 0; i < m; ++i) {
    const double t = turns * 2 * std::numbers::pi * i / (m - 1);
    const double r = 1 + 0.5 * t;
    v.push_back({r * std::cos(t), r * std::sin(t), 0});
    back.push_back({(r + 0.6) * std::cos(t), (r + 0.6) * std::sin(t), 0});
  }
  v.insert(v.end(), back.rbegin(), back.rend());
  if (shoelace_area(v) < 0) std::reverse(v.begin(), v.end());
  const auto convex = [&](std::size_t k) {
    const Vec3d& a = v[(k + v.size() - 1) % v.size()];
    return cross(v[k] - a, v[(k + 1) % v.size()] - v[k]).z > 0;
  };
  std::size_t k = 0;
  while (!convex(k)) ++k;
  std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>((k + v.size() - 1) % v.size()), v.end());
  return v;
}

// Concave: the spikes go first, then the disc inside them is clipped as a
// convex polygon would be, not as a fan of slivers, which shade black where
// single precision cannot tell a sliver's hits from its own surface.
TEST(Triangulate, ConcaveStarIsCoveredOnceWithFewThinTriangles) {
  for (int points : {5, 64, 400}) {
    const double thin = check_triangulation(star(points), 1.0, 0.0371);
    EXPECT_LT(thin, 0.01) << points << " points: share of the area in triangles with a corner under 1 degree";
  }
}

// A ring whose ears mostly hold other vertices: every one must still be found.
TEST(Triangulate, SpiralIsCoveredOnce) {
  const auto v = spiral(2000, 3);
  ASSERT_GT(shoelace_area(v), 0) << "counter-clockwise";
  check_triangulation(v, 11.5, 0.173);
}

}  // namespace
}  // namespace tracer
