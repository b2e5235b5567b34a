// The BVH and the grid find the same closest hits as testing every primitive.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "test_scenes.hpp"
#include "tracer/database.hpp"
#include "tracer/render.hpp"

namespace tracer {
namespace {

// Brute force over the packed primitive section, in the same float arithmetic.
std::optional<std::pair<float, std::uint32_t>> brute_force(const Database& db, const Ray& ray) {
  const SectionLayout& s = db.header.section(Section::prims);
  std::optional<std::pair<float, std::uint32_t>> best;
  float t_max = 1e30f;
  for (std::uint32_t i = 0; i < s.record_count; ++i) {
    const std::size_t byte = std::size_t{i} * sizeof(PrimRecord);
    PrimRecord p;
    std::memcpy(&p, db.pages[s.first_page + byte / db.header.page_size].data() +
                        byte % db.header.page_size, sizeof p);
    std::optional<float> t;
    if (p.kind == PrimKind::sphere) t = intersect_sphere(ray, p.p0, p.p1.x, 0.0f, t_max);
    else if (auto h = intersect_triangle(ray, p.p0, p.p1, p.p2, 0.0f, t_max)) t = h->t;
    if (t) {
      t_max = *t;
      best = {{*t, p.object}};
    }
  }
  return best;
}

// Rays from random points in random directions, over the cube the random
// test scenes fill; the same seed gives the same rays.
class RandomRays {
 public:
  explicit RandomRays(unsigned seed) : rng_(seed) {}
  Ray next() { return {{u_(rng_), u_(rng_), u_(rng_)}, {u_(rng_), u_(rng_), u_(rng_)}}; }

 private:
  std::mt19937 rng_;
  std::uniform_real_distribution<float> u_{-1.5f, 1.5f};
};

void expect_same_hits_as_brute_force(Accel accel) {
  const Scene scene = testing::random_scene(7, 400, 60);
  const Database db = build_database(scene, {.accel = accel, .page_size = 512});
  InMemoryPageSource pages(db);
  Tracer tracer(db.header, pages);
  RandomRays rays(11);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Ray ray = rays.next();
    RayStats stats;
    const auto expected = brute_force(db, ray);
    const auto got = tracer.closest_hit(ray, 0.0f, 1e30f, stats);
    ASSERT_EQ(expected.has_value(), got.has_value()) << "ray " << i;
    if (!got) continue;
    ++hits;
    EXPECT_EQ(expected->first, got->t) << "ray " << i;
    EXPECT_EQ(expected->second, got->prim.object) << "ray " << i;
    EXPECT_TRUE(tracer.occluded(ray, 0.0f, got->t * 1.01f, stats));
    EXPECT_FALSE(tracer.occluded(ray, 0.0f, got->t * 0.99f, stats));
  }
  EXPECT_GT(hits, 300);  // the test means something only if many rays hit
}

TEST(Bvh, ClosestHitsMatchBruteForce) { expect_same_hits_as_brute_force(Accel::bvh); }
TEST(Grid, ClosestHitsMatchBruteForce) { expect_same_hits_as_brute_force(Accel::grid); }

// The four-wide leaf test must give the scalar test's barycentrics bit for
// bit (shading interpolates normals with them), at every page size.
TEST(Bvh, LeafHitsCarryTheScalarTriangleResult) {
  const Scene scene = testing::random_scene(5, 400, 60);
  for (std::uint32_t page_size : {256u, 4096u}) {
    const Database db = build_database(scene, {.page_size = page_size});
    InMemoryPageSource pages(db);
    Tracer tracer(db.header, pages);
    RandomRays rays(23);
    int triangle_hits = 0;
    for (int i = 0; i < 2000; ++i) {
      const Ray ray = rays.next();
      RayStats stats;
      const auto got = tracer.closest_hit(ray, 0.0f, 1e30f, stats);
      if (!got || got->prim.kind == PrimKind::sphere) continue;
      ++triangle_hits;
      const auto h = intersect_triangle(ray, got->prim.p0, got->prim.p1, got->prim.p2, 0.0f, 1e30f);
      ASSERT_TRUE(h) << "ray " << i;
      EXPECT_EQ(h->t, got->t) << "ray " << i;
      EXPECT_EQ(h->u, got->u) << "ray " << i;
      EXPECT_EQ(h->v, got->v) << "ray " << i;
    }
    EXPECT_GT(triangle_hits, 100);
  }
}

TEST(Bvh, SinglePrimitiveSceneIsTraversable) {
  Scene s;
  s.materials.push_back({});
  s.objects.push_back({Sphere{{0, 0, 0}, 1}, 0});
  const Database db = build_database(s);
  InMemoryPageSource pages(db);
  Tracer tracer(db.header, pages);
  RayStats stats;
  const auto hit = tracer.closest_hit({{0, 0, -5}, {0, 0, 1}}, 0.0f, 1e30f, stats);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4.0f, 1e-5f);
}

TEST(Bvh, EmptySceneHasNoHits) {
  Scene s;
  const Database db = build_database(s);
  InMemoryPageSource pages(db);
  Tracer tracer(db.header, pages);
  RayStats stats;
  EXPECT_FALSE(tracer.closest_hit({{0, 0, -5}, {0, 0, 1}}, 0.0f, 1e30f, stats));
}

}  // namespace
}  // namespace tracer
