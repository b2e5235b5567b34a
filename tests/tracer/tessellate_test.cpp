// Tessellation: SPD's triangle counts, vertices on the surface with unit
// outward normals, triangles facing their normals, materials kept in order,
// inside-only spheres and cones rendered as before.
#include "tracer/tessellate.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "tracer/render.hpp"

namespace tracer {
namespace {

void expect_faces_its_normals(const Patch& p) {
  Vec3d face = cross(p.vertices[1] - p.vertices[0], p.vertices[2] - p.vertices[0]);
  Vec3d mean = p.normals[0] + p.normals[1] + p.normals[2];
  EXPECT_GT(dot(face, mean), 0);
}

TEST(Tessellate, SphereGivesTwelveRSquaredTrianglesOnTheSurface) {
  Sphere s{{1, 2, 3}, 0.5};
  for (int r : {1, 2, 6}) {
    auto tris = tessellate_sphere(s, r);
    ASSERT_EQ(tris.size(), std::size_t(12 * r * r));
    for (const Patch& p : tris)
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_NEAR(length(p.vertices[k] - s.center), 0.5, 1e-12);
        EXPECT_NEAR(length(p.normals[k]), 1, 1e-12);
        EXPECT_NEAR(dot(p.normals[k], p.vertices[k] - s.center), 0.5, 1e-12);  // outward
      }
    for (const Patch& p : tris) expect_faces_its_normals(p);
  }
}

TEST(Tessellate, NegativeRadiusSphereFacesInward) {
  for (const Patch& p : tessellate_sphere(Sphere{{0, 0, 0}, -2}, 2)) {
    EXPECT_LT(dot(p.normals[0], p.vertices[0]), 0);
    expect_faces_its_normals(p);
  }
}

TEST(Tessellate, CylinderGivesEightRTrianglesAroundTheAxis) {
  Cone c{{0, 0, 0}, 0.25, {1, 1, 0}, 0.25};
  for (int r : {1, 3}) {
    auto tris = tessellate_cone(c, r);
    ASSERT_EQ(tris.size(), std::size_t(8 * r));
    Vec3d axis = normalize(c.apex - c.base);
    for (const Patch& p : tris) {
      for (std::size_t k = 0; k < 3; ++k) {
        Vec3d rel = p.vertices[k] - c.base;
        EXPECT_NEAR(length(rel - axis * dot(rel, axis)), 0.25, 1e-12);
        EXPECT_NEAR(dot(p.normals[k], axis), 0, 1e-12);
      }
      expect_faces_its_normals(p);
    }
  }
}

TEST(Tessellate, AxisAlongZUsesTheFallbackDirection) {
  auto tris = tessellate_cone(Cone{{0, 0, 0}, 1, {0, 0, 2}, 0.5}, 2);
  ASSERT_EQ(tris.size(), 16u);
  for (const Patch& p : tris) expect_faces_its_normals(p);
}

TEST(Tessellate, TrueConeDropsItsZeroAreaApexTriangles) {
  auto tris = tessellate_cone(Cone{{0, 0, 0}, 1, {0, 1, 0}, 0}, 2);
  EXPECT_EQ(tris.size(), 8u);
}

TEST(Tessellate, SceneKeepsOrderAndMaterials) {
  Scene scene;
  scene.materials.resize(3);
  scene.objects.push_back({Sphere{{0, 0, 0}, 1}, 2});
  scene.objects.push_back({Polygon{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}, 0});
  scene.objects.push_back({Cone{{0, 0, 0}, 1, {1, 0, 0}, 1}, 1});
  tessellate(scene, 2);
  ASSERT_EQ(scene.objects.size(), 48u + 1u + 16u);
  EXPECT_EQ(scene.objects[0].material, 2u);
  EXPECT_TRUE(std::holds_alternative<Polygon>(scene.objects[48].shape));
  EXPECT_EQ(scene.objects.back().material, 1u);
  EXPECT_EQ(scene.polygon_count(), 65u);
}

std::vector<Color> render(const Scene& scene) {
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  RayStats stats;
  return render_frame(db.header, pages, {}, stats);
}

// Seen from outside with the light behind the eye, an inside-only sphere and
// cylinder show their far inner wall, which their near wall shadows: black.
TEST(Tessellate, InsideOnlySpheresAndConesLookTheSame) {
  Scene scene;
  scene.camera = {{0, 0, 6}, {0, 0, 0}, {0, 1, 0}, 50.0, 0.01, 24, 24};
  scene.background = {0.2f, 0.3f, 0.5f};
  scene.lights = {{{0, 0, 8}, {1, 1, 1}}};
  scene.materials.resize(1);
  scene.objects.push_back({Sphere{{-1.2, 0, 0}, -1}, 0});
  scene.objects.push_back({Cone{{1.2, -1, 0}, -0.8, {1.2, 1, 0}, -0.8}, 0});
  const std::vector<Color> analytic = render(scene);
  EXPECT_EQ(analytic[12 * 24 + 5], (Color{0, 0, 0}));   // the sphere's centre
  EXPECT_EQ(analytic[12 * 24 + 18], (Color{0, 0, 0}));  // the cylinder's axis
  tessellate(scene, 4);
  EXPECT_EQ(render(scene), analytic);
}

TEST(Tessellate, RejectsResolutionOutOfRange) {
  Scene scene;
  EXPECT_THROW(tessellate(scene, 0), std::invalid_argument);
  EXPECT_THROW(tessellate(scene, kMaxTessellation + 1), std::invalid_argument);
}

}  // namespace
}  // namespace tracer
