// The shadow-ray policy (TraceOptions::shadow_rays_to_all_lights): casting a
// shadow ray to every light at every hit changes the counts and the work,
// never the image, because a light behind the surface contributes nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "test_scenes.hpp"
#include "tracer/render.hpp"

namespace tracer {
namespace {

constexpr int kSize = 32;

struct Frame {
  std::vector<Color> pixels;
  RayStats stats;
};

Frame render(const Scene& scene, bool all_lights) {
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  Frame f;
  f.pixels = render_frame(db.header, pages, {.shadow_rays_to_all_lights = all_lights}, f.stats);
  return f;
}

// A lit floor seen from above, with one light above and one below it.
Scene floor_with_light_below() {
  Scene s;
  s.name = "floor";
  s.camera = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 30.0, 0.01, kSize, kSize};
  s.lights = {{{0, 0, 3}, {1, 1, 1}}, {{0, 0, -3}, {1, 1, 1}}};
  s.materials = {{{1, 1, 1}, 0.9, 0.0, 0, 0, 1}};
  s.objects.push_back({Polygon{{{-9, -9, 0}, {9, -9, 0}, {9, 9, 0}, {-9, 9, 0}}}, 0});
  return s;
}

TEST(ShadowRays, AllLightsGiveTheSameImageWithMoreShadowRays) {
  const Scene scene = testing::showcase_scene(kSize);
  const Frame facing = render(scene, false), all = render(scene, true);
  EXPECT_EQ(all.pixels, facing.pixels);
  EXPECT_GT(all.stats.shadow, facing.stats.shadow);
  EXPECT_EQ(all.stats.primary, facing.stats.primary);
  EXPECT_EQ(all.stats.reflected, facing.stats.reflected);
  EXPECT_EQ(all.stats.refracted, facing.stats.refracted);
  EXPECT_EQ(all.stats.shadow % scene.lights.size(), 0u);  // every hit, every light
  EXPECT_GT(all.stats.box_tests, facing.stats.box_tests);
}

TEST(ShadowRays, LightBehindTheSurfaceAddsNothingButIsCountedUnderAll) {
  const Scene scene = floor_with_light_below();
  const Frame facing = render(scene, false), all = render(scene, true);
  ASSERT_EQ(facing.stats.primary_hits, std::uint64_t(kSize) * kSize);
  EXPECT_EQ(facing.stats.shadow, facing.stats.primary_hits);  // the light above only
  EXPECT_EQ(all.stats.shadow, 2 * all.stats.primary_hits);
  EXPECT_EQ(all.pixels, facing.pixels);
  // The light below contributes nothing: the floor shows the light above alone.
  Scene above = scene;
  above.lights.pop_back();
  const Frame one = render(above, true);
  const float scale = std::sqrt(2.0f);  // light intensity is 1/sqrt(#lights)
  const Color centre = all.pixels[std::size_t(kSize / 2) * kSize + kSize / 2];
  const Color alone = one.pixels[std::size_t(kSize / 2) * kSize + kSize / 2];
  EXPECT_NEAR(centre.r * scale, alone.r, 1e-5f);
  EXPECT_GT(centre.r, 0.0f);
}

}  // namespace
}  // namespace tracer
