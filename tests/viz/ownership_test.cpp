// Pixel-ownership images: one distinct colour per node, stable colours,
// overlay blending, size checks.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <tuple>

#include "app/viz/colour.hpp"
#include "app/viz/ownership.hpp"

namespace viz {
namespace {

std::set<std::tuple<int, int, int>> distinct_colours(const tracer::Image& img) {
  const tracer::Rgb8Image bytes = img.to_rgb8();
  std::set<std::tuple<int, int, int>> out;
  for (std::size_t i = 0; i < bytes.rgb.size(); i += 3) out.insert({bytes.rgb[i], bytes.rgb[i + 1], bytes.rgb[i + 2]});
  return out;
}

TEST(Ownership, UsesExactlyOneColourPerNode) {
  for (int nodes : {1, 2, 7, 16, 64, 256}) {
    const int width = 32, height = 16;
    std::vector<std::uint16_t> owners;
    // Tiles of 2x2 pixels dealt round-robin, as a farmer might.
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) owners.push_back(static_cast<std::uint16_t>(((y / 2) * (width / 2) + x / 2) % nodes));
    EXPECT_EQ(distinct_colours(ownership_image(width, height, owners)).size(), static_cast<std::size_t>(std::min(nodes, 128)))
        << nodes << " nodes";
  }
}

TEST(Ownership, FirstThousandNodeColoursAreDistinct) {
  std::set<std::tuple<int, int, int>> seen;
  for (int i = 0; i < 1024; ++i) {
    const Rgb8 c = node_colour(i);
    seen.insert({c.r, c.g, c.b});
  }
  EXPECT_EQ(seen.size(), 1024u);
}

TEST(Ownership, ColourOfANodeIsStable) {
  const tracer::Image a = ownership_image(2, 1, {5, 9});
  const tracer::Image b = ownership_image(1, 1, {9});
  EXPECT_EQ(a.at(1, 0), b.at(0, 0));
  EXPECT_NE(a.at(0, 0), a.at(1, 0));
}

TEST(Ownership, ColoursSurviveTheByteConversion) {
  const Rgb8 c = node_colour(3);
  const tracer::Rgb8Image bytes = ownership_image(1, 1, {3}).to_rgb8();
  EXPECT_EQ(bytes.rgb[0], c.r);
  EXPECT_EQ(bytes.rgb[1], c.g);
  EXPECT_EQ(bytes.rgb[2], c.b);
}

TEST(Ownership, OverlayMixesRenderAndOwner) {
  tracer::Image render(2, 1);
  render.at(0, 0) = {1, 1, 1};
  const std::vector<std::uint16_t> owners{0, 1};
  const tracer::Image owner = ownership_image(2, 1, owners);
  const tracer::Image mixed = ownership_overlay(render, owners, 0.25f);
  EXPECT_FLOAT_EQ(mixed.at(0, 0).r, 0.75f + 0.25f * owner.at(0, 0).r);
  EXPECT_FLOAT_EQ(mixed.at(1, 0).g, 0.25f * owner.at(1, 0).g);
  const tracer::Image pure = ownership_overlay(render, owners, 1.0f);
  EXPECT_EQ(pure.at(1, 0), owner.at(1, 0));
}

TEST(Ownership, RejectsWrongOwnerCount) {
  EXPECT_THROW(ownership_image(4, 4, std::vector<std::uint16_t>(15)), std::invalid_argument);
  EXPECT_THROW(ownership_image(0, 4, {}), std::invalid_argument);
  EXPECT_THROW(ownership_overlay(tracer::Image(2, 2), {1, 2, 3}), std::invalid_argument);
}

}  // namespace
}  // namespace viz
