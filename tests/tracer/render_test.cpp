// Renders of a small scene: independent of page size, of the page cache, of
// how pixels are split; BVH and grid agree; SPD mode counts rays as specified.
// A lit polygon of thousands of vertices does not shadow itself. A ray hook
// runs before every ray and changes nothing.
#include "tracer/render.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <thread>
#include <vector>

#include "test_scenes.hpp"
#include "tracer/generators.hpp"

namespace tracer {
namespace {

constexpr int kSize = 40;

std::vector<Color> render(const Scene& scene, BuildOptions build, TraceOptions trace = {},
                          RayStats* stats_out = nullptr) {
  const Database db = build_database(scene, build);
  InMemoryPageSource pages(db);
  RayStats stats;
  auto image = render_frame(db.header, pages, trace, stats);
  if (stats_out) *stats_out = stats;
  return image;
}

// Keeps only the page read last, in one buffer: the smallest cache a node may have.
class OnePageCache final : public PageSource {
 public:
  explicit OnePageCache(const Database& db) : db_(db), buffer_(db.header.page_size) {}
  const std::byte* page(PageId id) override {
    std::memset(buffer_.data(), 0xff, buffer_.size());  // poison the previous page
    std::memcpy(buffer_.data(), db_.pages[id].data(), buffer_.size());
    return buffer_.data();
  }

 private:
  const Database& db_;
  std::vector<std::byte> buffer_;
};

TEST(Render, ImageIsBitIdenticalForEveryPageSize) {
  const Scene scene = testing::showcase_scene(kSize);
  const auto reference = render(scene, {.page_size = 65536});
  EXPECT_EQ(render(scene, {.page_size = 256}), reference);
  EXPECT_EQ(render(scene, {.page_size = 1024}), reference);
}

// The treelet layout renumbers the same tree: every ray meets the same boxes
// and primitives in the same order, but goes down it over fewer pages.
TEST(Render, TreeletLayoutGivesTheSameImageOverFewerPages) {
  Scene scene = generate_scene("teapot:3");
  scene.camera.width = scene.camera.height = 96;
  for (std::uint32_t page_size : {256u, 1024u, 4096u}) {
    RayStats depth_first, treelet;
    const auto reference = render(scene, {.bvh_layout = BvhLayout::depth_first, .page_size = page_size}, {},
                                  &depth_first);
    EXPECT_EQ(render(scene, {.bvh_layout = BvhLayout::treelet, .page_size = page_size}, {}, &treelet), reference)
        << page_size;
    EXPECT_EQ(treelet.box_tests, depth_first.box_tests) << page_size;
    EXPECT_EQ(treelet.prim_tests, depth_first.prim_tests) << page_size;
    EXPECT_EQ(treelet.record_reads, depth_first.record_reads) << page_size;
    EXPECT_LT(treelet.page_calls, depth_first.page_calls) << page_size;
    EXPECT_LT(treelet.distinct_pages, depth_first.distinct_pages) << page_size;
  }
}

TEST(Render, OnePageCacheGivesTheSameImage) {
  const Scene scene = testing::showcase_scene(kSize);
  const Database db = build_database(scene, {.page_size = 256});
  InMemoryPageSource all(db);
  OnePageCache one(db);
  RayStats a, b;
  EXPECT_EQ(render_frame(db.header, one, {}, b), render_frame(db.header, all, {}, a));
  EXPECT_EQ(a.page_calls, b.page_calls);
}

TEST(Render, PixelsDoNotDependOnTraceOrder) {
  const Scene scene = testing::showcase_scene(kSize);
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  RayStats stats;
  const auto frame = render_frame(db.header, pages, {}, stats);
  Tracer tracer(db.header, pages);
  for (int y = kSize - 1; y >= 0; y -= 3)
    for (int x = kSize - 1; x >= 0; x -= 5)
      EXPECT_EQ(tracer.trace_pixel(x, y, stats), frame[std::size_t(y) * kSize + x]);
}

// The ray hook is called once before every ray cast, eye, shadow and
// secondary alike, and changes nothing of the render: same pixels, same
// counts, the same pages read.
TEST(Render, TheRayHookRunsBeforeEveryRayAndChangesNothing) {
  const Scene scene = testing::showcase_scene(kSize);
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  RayStats plain_stats, hooked_stats;
  Tracer plain(db.header, pages), hooked(db.header, pages);
  std::uint64_t calls = 0;
  hooked.set_ray_hook([](void* count) { ++*static_cast<std::uint64_t*>(count); }, &calls);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      ASSERT_EQ(hooked.trace_pixel(x, y, hooked_stats), plain.trace_pixel(x, y, plain_stats)) << x << ", " << y;
  EXPECT_EQ(calls, hooked_stats.rays());
  EXPECT_GT(hooked_stats.shadow + hooked_stats.reflected + hooked_stats.refracted, 0u);
  EXPECT_EQ(hooked_stats.box_tests, plain_stats.box_tests);
  EXPECT_EQ(hooked_stats.page_calls, plain_stats.page_calls);
  EXPECT_EQ(hooked_stats.distinct_pages, plain_stats.distinct_pages);
}

TEST(Render, BvhAndGridGiveTheSameImage) {
  const Scene scene = testing::showcase_scene(kSize);
  EXPECT_EQ(render(scene, {.accel = Accel::grid}), render(scene, {.accel = Accel::bvh}));
}

TEST(Render, SceneShowsEveryMaterial) {
  const Scene scene = testing::showcase_scene(kSize);
  RayStats stats;
  const auto image = render(scene, {}, {}, &stats);
  EXPECT_EQ(stats.primary, std::uint64_t(kSize) * kSize);
  EXPECT_GT(stats.primary_hits, stats.primary / 2);
  EXPECT_GT(stats.shadow, 0u);
  EXPECT_GT(stats.reflected, 0u);
  EXPECT_GT(stats.refracted, 0u);
  EXPECT_GT(stats.pages_per_sample(), 1.0);
  int background = 0;
  for (const Color& c : image) background += c == scene.background;
  EXPECT_GT(background, 0);
  EXPECT_LT(background, kSize * kSize / 2);
}

TEST(Render, SpdProcedureTracesCornersAndAveragesThem) {
  Scene scene = testing::showcase_scene(8);
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  RayStats stats;
  const auto image = render_frame(db.header, pages, {.spd_procedure = true}, stats);
  EXPECT_EQ(stats.primary, 9u * 9u);
  Tracer tracer(db.header, pages, {.spd_procedure = true});
  const Color expected = Tracer::average_corners(
      tracer.trace_sample(3, 4, stats), tracer.trace_sample(4, 4, stats),
      tracer.trace_sample(3, 5, stats), tracer.trace_sample(4, 5, stats));
  EXPECT_EQ(image[4 * 8 + 3], expected);
}

bool same_stats(const RayStats& a, const RayStats& b) {
  return a.primary == b.primary && a.primary_hits == b.primary_hits && a.shadow == b.shadow &&
         a.reflected == b.reflected && a.refracted == b.refracted && a.box_tests == b.box_tests &&
         a.prim_tests == b.prim_tests && a.record_reads == b.record_reads && a.page_calls == b.page_calls &&
         a.samples == b.samples && a.distinct_pages == b.distinct_pages;
}

// The frame on several threads is the frame on one, pixels and counts, with
// and without SPD corner samples (which go in bands of rows: 70 rows make
// three, the last one short).
TEST(Render, ThreadsGiveTheSameImageAndTheSameCounts) {
  Scene scene = testing::showcase_scene(kSize);
  scene.camera.width = 23;
  scene.camera.height = 70;
  const Database db = build_database(scene, {.page_size = 256});
  for (const bool spd : {false, true}) {
    const TraceOptions trace{.spd_procedure = spd};
    InMemoryPageSource pages(db);
    RayStats one;
    const std::vector<Color> expected = render_frame(db.header, pages, trace, one);
    for (unsigned threads : {0u, 1u, 2u, 3u, 8u, 100u}) {
      RayStats stats;
      const std::vector<Color> image = render_frame(db, trace, stats, threads);
      ASSERT_EQ(image.size(), expected.size());
      EXPECT_EQ(std::memcmp(image.data(), expected.data(), image.size() * sizeof(Color)), 0)
          << threads << " threads, spd " << spd;
      EXPECT_TRUE(same_stats(stats, one)) << threads << " threads, spd " << spd;
    }
  }
}

// Progress comes on the calling thread only, never falls, and ends at the last row.
TEST(Render, ThreadedProgressIsOnTheCallersThreadAndNeverFalls) {
  Scene scene = testing::showcase_scene(kSize);
  const Database db = build_database(scene);
  for (const bool spd : {false, true}) {
    std::vector<int> seen;
    bool elsewhere = false;
    const auto caller = std::this_thread::get_id();
    RayStats stats;
    render_frame(db, {.spd_procedure = spd}, stats, 4, [&](int rows) {
      elsewhere |= std::this_thread::get_id() != caller;
      seen.push_back(rows);
    });
    EXPECT_FALSE(elsewhere);
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_EQ(seen.back(), kSize);
  }
}

TEST(Render, MaxDepthOneTracesNoSecondaryRays) {
  RayStats stats;
  render(testing::showcase_scene(16), {}, {.max_depth = 1}, &stats);
  EXPECT_EQ(stats.reflected + stats.refracted, 0u);
}

// A disc of radius 1.5 as a 2000-gon facing the camera and the light. Fanned
// from one vertex, its slivers' hit distances were off by more than the
// shadow rays' offset, which then started below the disc and hit it.
TEST(Render, ManySidedDiscIsLitEverywhere) {
  constexpr int kVertices = 2000;
  Scene s;
  s.name = "disc";
  s.camera = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 45.0, 1.0, 48, 48};
  s.background = {0, 0, 1};
  s.lights = {{{0, 0, 10}, {1, 1, 1}}};
  s.materials = {{{1, 0, 0}, 1.0, 0.0, 0, 0, 1}};
  Polygon disc;
  for (int i = 0; i < kVertices; ++i) {
    const double a = 2 * std::numbers::pi * i / kVertices;
    disc.vertices.push_back({1.5 * std::cos(a), 1.5 * std::sin(a), 0});
  }
  s.objects.push_back({disc, 0});
  int lit = 0, unlit = 0;
  for (const Color& c : render(s, {})) {
    if (c == s.background) continue;
    if (c.r > 0)
      ++lit;
    else
      ++unlit;
  }
  EXPECT_GT(lit, 48 * 48 / 4);
  EXPECT_EQ(unlit, 0);
}

TEST(Render, BackgroundWhenNothingIsHit) {
  Scene scene = testing::showcase_scene(4);
  scene.camera.at = scene.camera.from * 2.0;  // look away from everything
  for (const Color& c : render(scene, {})) EXPECT_EQ(c, scene.background);
}

}  // namespace
}  // namespace tracer
