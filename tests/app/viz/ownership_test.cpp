// Pixel-ownership images: one distinct colour per node, stable colours,
// overlay blending, size checks; their pictures with a key.
#include "app/viz/ownership.hpp"

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <tuple>

#include "app/viz/colour.hpp"
#include "picture_check.hpp"

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

std::vector<KeyEntry> key_of(int nodes) {
  std::vector<KeyEntry> key;
  for (int n = 0; n < nodes; ++n) key.push_back({std::to_string(n), node_colour(n)});
  return key;
}

// Pixels of exactly colour c.
int pixels_of(const tracer::Rgb8Image& img, Rgb8 c) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) n += test::pixel(img, x, y) == c;
  return n;
}

// Every pixel owned by node 0, so colours of other nodes come from the key.
TEST(OwnershipPicture, KeyShowsEveryNodesColour) {
  for (int nodes : {1, 4, 16, 64, 300}) {
    const tracer::Image owners = ownership_image(12, 10, std::vector<std::uint16_t>(120, 0));
    const tracer::Image picture = ownership_picture(owners, key_of(nodes));
    EXPECT_GT(picture.width(), owners.width());
    EXPECT_GT(picture.height(), owners.height());
    const tracer::Rgb8Image bytes = picture.to_rgb8();
    for (int n = 1; n < nodes; ++n) EXPECT_GE(pixels_of(bytes, node_colour(n)), 16) << n << " of " << nodes << " nodes";
  }
}

// A small image is enlarged by a whole factor with its pixels kept sharp:
// the picture holds many pixels of each of its two owners' colours.
TEST(OwnershipPicture, SmallImagesAreEnlargedSharply) {
  std::vector<std::uint16_t> owners(12 * 10, 3);
  for (int i = 0; i < 60; ++i) owners[static_cast<std::size_t>(i)] = 5;
  const tracer::Image picture = ownership_picture(ownership_image(12, 10, owners), {});
  EXPECT_GE(picture.width(), 256);
  const tracer::Rgb8Image bytes = picture.to_rgb8();
  const int factor = (256 + 11) / 12;
  EXPECT_GE(pixels_of(bytes, node_colour(5)), 60 * factor * factor);
  EXPECT_GE(pixels_of(bytes, node_colour(3)), 60 * factor * factor);
}

// Labels are drawn as text: dark pixels in the picture where the image has none.
TEST(OwnershipPicture, KeyIsLabelled) {
  const tracer::Image owners = ownership_image(300, 200, std::vector<std::uint16_t>(60000, 1));
  const tracer::Rgb8Image unlabelled = ownership_picture(owners, {{"", node_colour(0)}}).to_rgb8();
  const tracer::Rgb8Image labelled = ownership_picture(owners, key_of(4)).to_rgb8();
  EXPECT_EQ(test::dark_pixels(unlabelled, 0, 0, unlabelled.width, unlabelled.height), 0);
  EXPECT_GT(test::dark_pixels(labelled, 0, 0, labelled.width, labelled.height), 10);
  EXPECT_GT(test::intermediate_greys(labelled, 0, 0, labelled.width, labelled.height), 10);
}

TEST(OwnershipPicture, RejectsEmptyAndHugeImages) {
  EXPECT_THROW(ownership_picture(tracer::Image{}, key_of(2)), std::invalid_argument);
  EXPECT_THROW(ownership_picture(tracer::Image(20000, 1), key_of(2)), std::invalid_argument);
}

}  // namespace
}  // namespace viz
