// The BVH and the grid find the same closest hits as testing every primitive;
// the treelet layout renumbers the same tree; any number of build threads
// builds the same tree.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <random>

#include "test_scenes.hpp"
#include "tracer/bvh.hpp"
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

void expect_same_hits_as_brute_force(Accel accel, const Scene& scene = testing::random_scene(7, 400, 60),
                                     const std::function<Ray(RandomRays&)>& next = &RandomRays::next) {
  const Database db = build_database(scene, {.accel = accel, .page_size = 512});
  if (accel == Accel::grid) {
    EXPECT_GT(db.stats.grid_subgrids, 0u);  // both levels are walked
  }
  InMemoryPageSource pages(db);
  Tracer tracer(db.header, pages);
  RandomRays rays(11);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Ray ray = next(rays);
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

// Two clusters of small triangles and spheres in opposite corners of the
// cube, empty space between: the grid's walk jumps over the empty cells far
// from the clusters (records.hpp), and must meet the same primitives as
// brute force on rays aimed at the clusters from anywhere in the cube.
TEST(Grid, JumpsOverEmptySpaceToTheSameHits) {
  Scene scene = testing::random_scene(5, 600, 40);
  // A point of the cube moved into the corner its x coordinate picks.
  const auto cornered = [](const Vec3d& p) {
    Vec3d q;
    for (int a = 0; a < 3; ++a) q[a] = (p.x < 0 ? -1.2 : 1.2) + 0.15 * p[a];
    return q;
  };
  for (auto& object : scene.objects) {
    if (auto* polygon = std::get_if<Polygon>(&object.shape)) {
      const Vec3d first = polygon->vertices[0], moved = cornered(first);
      for (Vec3d& v : polygon->vertices) v = moved + (v - first) * 0.3;
    } else if (auto* sphere = std::get_if<Sphere>(&object.shape)) {
      sphere->center = cornered(sphere->center);
      sphere->radius *= 0.5;
    }
  }
  const Database db = build_database(scene, {.accel = Accel::grid, .page_size = 512});
  const SectionLayout& cells = db.header.section(Section::grid_cells);
  std::uint32_t farthest = 0;
  for (std::uint32_t i = 0; i < cells.record_count; ++i) {
    GridCell c;
    const std::size_t byte = std::size_t{i} * sizeof c;
    std::memcpy(&c, db.pages[cells.first_page + byte / 512].data() + byte % 512, sizeof c);
    if (c.count == 0) farthest = std::max(farthest, c.first & 0xffff);  // chessboard
  }
  EXPECT_GE(farthest, 4u) << "no empty cell far enough from the clusters to be jumped over";
  expect_same_hits_as_brute_force(Accel::grid, scene, [&](RandomRays& rays) {
    const Ray from = rays.next();
    const Vec3d target = cornered(Vec3d{from.dir.x, from.dir.y, from.dir.z} * (1 / 1.5));
    const Vec3f aim{float(target.x), float(target.y), float(target.z)};
    return Ray{from.origin, aim - from.origin};
  });
}

// The four-wide leaf test (and the grid's four-wide test of triangles copied
// out of their pages) must give the scalar test's barycentrics bit for bit
// (shading interpolates normals with them), at every page size.
TEST(Bvh, LeafHitsCarryTheScalarTriangleResult) {
  const Scene scene = testing::random_scene(5, 400, 60);
  for (const Accel accel : {Accel::bvh, Accel::grid})
    for (std::uint32_t page_size : {256u, 4096u}) {
      const Database db = build_database(scene, {.accel = accel, .page_size = page_size});
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

// Spheres near the limit of float, more than a leaf holds: the bounds of the
// outer ones add up past it, and their centroid box is wider than a float can
// say. The builds must
// neither divide infinity by infinity into a bin number nor cast a value no
// int can hold (undefined behaviour, which the sanitizer build traps), and
// the sphere at the origin is still found.
TEST(Bvh, CoordinatesNearTheLimitOfFloatBuildAndTrace) {
  for (const Accel accel : {Accel::bvh, Accel::grid}) {
    Scene s;
    s.materials.push_back({});
    for (const double x : {0.0, 10.0, 20.0})
      for (const double y : {3e38, 0.0, -3e38}) s.objects.push_back({Sphere{{x, y, 0}, 1}, 0});
    const Database db = build_database(s, BuildOptions{.accel = accel});
    InMemoryPageSource pages(db);
    Tracer tracer(db.header, pages);
    RayStats stats;
    const auto hit = tracer.closest_hit({{0, 0, -5}, {0, 0, 1}}, 0.0f, 1e30f, stats);
    ASSERT_TRUE(hit) << (accel == Accel::bvh ? "bvh" : "grid");
    EXPECT_NEAR(hit->t, 4.0f, 1e-5f);
  }
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

namespace tracer {
namespace {

BuildRefs random_boxes(unsigned seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> at(-10.0f, 10.0f), size(0.01f, 1.0f);
  BuildRefs refs;
  for (int i = 0; i < count; ++i) {
    const Vec3f lo{at(rng), at(rng), at(rng)};
    refs.bounds.push_back({lo, lo + Vec3f{size(rng), size(rng), size(rng)}});
    refs.prim.push_back(static_cast<std::uint32_t>(i));
    refs.triangle.push_back(false);
  }
  return refs;
}

// Walks both trees from their roots in step: the same lanes everywhere, every
// node of `relaid` reached once, each after its parent.
void expect_same_tree(const BvhBuild& original, const BvhBuild& relaid, std::uint32_t a, std::uint32_t b,
                      std::vector<int>& visits) {
  ++visits[b];
  const BvhNode& x = original.nodes[a];
  const BvhNode& y = relaid.nodes[b];
  EXPECT_EQ(0, std::memcmp(x.lo, y.lo, sizeof x.lo));
  EXPECT_EQ(0, std::memcmp(x.hi, y.hi, sizeof x.hi));
  for (int lane = 0; lane < 4; ++lane) {
    ASSERT_EQ(x.count[lane], y.count[lane]);
    ASSERT_EQ(is_inner_lane(x, lane), is_inner_lane(y, lane));
    if (!is_inner_lane(x, lane)) {
      EXPECT_EQ(x.child[lane], y.child[lane]);  // a leaf's first primitive, or an unused lane
      continue;
    }
    ASSERT_LT(y.child[lane], relaid.nodes.size());
    EXPECT_GT(y.child[lane], b);
    expect_same_tree(original, relaid, x.child[lane], y.child[lane], visits);
  }
}

TEST(BvhLayout, TreeletsRenumberTheSameTree) {
  const BuildRefs refs = random_boxes(3, 3000);
  const BvhBuild original = build_bvh(refs, 4);
  ASSERT_GT(original.nodes.size(), 100u);
  for (std::uint32_t per_page : {2u, 8u, 32u}) {
    BvhBuild relaid = original;
    lay_out_treelets(relaid, per_page);
    ASSERT_EQ(relaid.nodes.size(), original.nodes.size());
    EXPECT_EQ(relaid.order, original.order);
    std::vector<int> visits(relaid.nodes.size(), 0);
    expect_same_tree(original, relaid, 0, 0, visits);
    EXPECT_EQ(std::count(visits.begin(), visits.end(), 1), static_cast<long>(visits.size())) << per_page;
  }
}

float area_of(const BvhNode& node) {
  Box3f box;
  for (int lane = 0; lane < 4; ++lane)
    if (const Box3f b = lane_box(node, lane); !b.empty()) box.extend(b);
  return box.half_area();
}

// A page is a treelet: on the first page every node but the root hangs from
// a node of that page, and each node was the largest on offer when it was
// placed, so no child left off the page (except the last node's, offered
// after the page was full) is larger than the page's last node.
void expect_first_page_is_a_treelet(const BvhBuild& bvh, std::uint32_t per_page) {
  std::vector<std::uint32_t> parent(bvh.nodes.size(), ~0u);
  for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i)
    for (int lane = 0; lane < 4; ++lane)
      if (is_inner_lane(bvh.nodes[i], lane)) parent[bvh.nodes[i].child[lane]] = i;
  const float last = area_of(bvh.nodes[per_page - 1]);
  for (std::uint32_t i = 1; i < per_page; ++i) EXPECT_LT(parent[i], per_page) << "node " << i;
  for (std::uint32_t i = per_page; i < bvh.nodes.size(); ++i) {
    if (parent[i] < per_page - 1) {
      EXPECT_LE(area_of(bvh.nodes[i]), last) << "node " << i;
    }
  }
}

TEST(BvhLayout, FirstPageIsTheLargestTopOfTheTree) {
  BvhBuild bvh = build_bvh(random_boxes(5, 3000), 4);
  for (std::uint32_t per_page : {4u, 8u, 16u}) {
    BvhBuild relaid = bvh;
    lay_out_treelets(relaid, per_page);
    expect_first_page_is_a_treelet(relaid, per_page);
  }
}

// Random boxes, some of them triangles, plus a pile of identical boxes (no
// centroid extent: halved, not binned) and boxes touching the planes
// through 0 with both signs of zero, where min and max meet ties.
BuildRefs awkward_boxes(unsigned seed, int count) {
  BuildRefs refs = random_boxes(seed, count);
  for (std::size_t i = 0; i < refs.triangle.size(); i += 3) refs.triangle[i] = true;
  const auto add = [&](const Box3f& b) {
    refs.bounds.push_back(b);
    refs.prim.push_back(static_cast<std::uint32_t>(refs.prim.size()));
    refs.triangle.push_back(true);
  };
  for (int i = 0; i < count / 10; ++i) add({{1, 2, 3}, {1.5f, 2.5f, 3.5f}});
  for (int i = 0; i < count / 10; ++i) {
    const float zero = i % 2 ? -0.0f : 0.0f, w = 0.1f + 0.001f * static_cast<float>(i % 97);
    add({{zero, zero, static_cast<float>(i % 13)}, {w, w, static_cast<float>(i % 13) + w}});
  }
  return refs;
}

void expect_identical(const BvhBuild& expected, const BvhBuild& got, const std::string& what) {
  ASSERT_EQ(expected.nodes.size(), got.nodes.size()) << what;
  EXPECT_EQ(0, std::memcmp(expected.nodes.data(), got.nodes.data(), expected.nodes.size() * sizeof(BvhNode))) << what;
  EXPECT_EQ(expected.order, got.order) << what;
  EXPECT_EQ(expected.depth, got.depth) << what;
}

// Large enough that the default thresholds split the top nodes into chunks
// and build subtrees on threads of their own.
TEST(BvhParallel, SameTreeOnAnyThreadCount) {
  const BuildRefs refs = awkward_boxes(13, 150000);
  const BvhBuild one = build_bvh(refs, 4);
  ASSERT_GT(one.nodes.size(), 10000u);
  for (unsigned threads : {0u, 2u, 3u, 8u})
    expect_identical(one, build_bvh(refs, 4, {.threads = threads}), std::to_string(threads) + " threads");
}

// Tiny thresholds put most nodes on the chunked, threaded paths: they must
// give what the sequential build gives, with any chunk size.
TEST(BvhParallel, ChunkedNodesMatchTheSequentialBuild) {
  const BuildRefs refs = awkward_boxes(17, 8000);
  const BvhBuild sequential = build_bvh(refs, 4);
  for (unsigned threads : {1u, 2u, 3u, 8u})
    for (std::uint32_t chunk : {7u, 64u}) {
      const BvhParallelism par{.threads = threads, .large_node = 4 * chunk, .chunk = chunk};
      expect_identical(sequential, build_bvh(refs, 4, par),
                       std::to_string(threads) + " threads, chunks of " + std::to_string(chunk));
    }
}

TEST(BvhParallel, OneAndNoReferencesOnManyThreads) {
  const BuildRefs one = random_boxes(1, 1), none;
  const BvhParallelism par{.threads = 8, .large_node = 2, .chunk = 1};
  expect_identical(build_bvh(one, 4), build_bvh(one, 4, par), "one reference");
  expect_identical(build_bvh(none, 4), build_bvh(none, 4, par), "no reference");
}

}  // namespace
}  // namespace tracer
