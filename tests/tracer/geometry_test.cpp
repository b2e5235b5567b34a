// Intersection routines against analytic answers.
#include "tracer/geometry.hpp"

#include <gtest/gtest.h>

namespace tracer {
namespace {

constexpr float kInf = 1e30f;

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

TEST(Triangulate, NonConvexPolygonCoversItsArea) {
  // An L shape (area 3), counter-clockwise, first corner convex.
  const std::vector<Vec3d> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  const auto tris = triangulate_polygon(l);
  ASSERT_EQ(tris.size(), 4u);
  double area = 0;
  for (const auto& t : tris) {
    const Vec3d n = cross(l[t[1]] - l[t[0]], l[t[2]] - l[t[0]]);
    EXPECT_GT(n.z, 0) << "every triangle keeps the polygon's winding";
    area += 0.5 * n.z;
  }
  EXPECT_NEAR(area, 3.0, 1e-12);
}

}  // namespace
}  // namespace tracer
