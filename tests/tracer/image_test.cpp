// Image: the one float->byte conversion, an image taking its pixels,
// PNG/PPM round trips, and writes that never leave a partial file behind.
#include "tracer/image.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

namespace tracer {
namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  fs::path dir = fs::path(::testing::TempDir()) / ("vmpray_image_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Image gradient(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) = {x / float(w - 1), y / float(h - 1), (x + y) % 3 == 0 ? 2.0f : -0.5f};
  return img;
}

TEST(Image, ToByteClampsAndRoundsHalfUp) {
  EXPECT_EQ(to_byte(0.0f), 0);
  EXPECT_EQ(to_byte(1.0f), 255);
  EXPECT_EQ(to_byte(0.5f), 128);
  EXPECT_EQ(to_byte(1.0f / 255.0f), 1);
  EXPECT_EQ(to_byte(-3.0f), 0);
  EXPECT_EQ(to_byte(7.0f), 255);
  EXPECT_EQ(to_byte(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(to_byte(std::numeric_limits<float>::infinity()), 255);
}

TEST(Image, ToRgb8IsRowMajorFromTopLeft) {
  Image img(2, 2);
  img.at(1, 0) = {1, 0, 0};
  img.at(0, 1) = {0, 0, 1};
  Rgb8Image b = img.to_rgb8();
  ASSERT_EQ(b.rgb.size(), 12u);
  EXPECT_EQ(b.rgb[3], 255);  // (1,0) red
  EXPECT_EQ(b.rgb[8], 255);  // (0,1) blue
  EXPECT_EQ(b.rgb[0], 0);
}

TEST(Image, RejectsNonPositiveSize) { EXPECT_THROW(Image(0, 3), std::invalid_argument); }

TEST(Image, TakesPixelsThatFillIt) {
  std::vector<Color> pixels(6);
  pixels[4] = {0.25f, 0.5f, 1.0f};  // (1,1), row-major from the top row
  const Color* held = pixels.data();
  const Image img(3, 2, std::move(pixels));
  EXPECT_EQ(img.at(1, 1).g, 0.5f);
  EXPECT_EQ(img.pixels().data(), held);  // the very buffer, not a copy
  EXPECT_THROW(Image(3, 2, std::vector<Color>(5)), std::invalid_argument);
  EXPECT_THROW(Image(0, 2, std::vector<Color>{}), std::invalid_argument);
}

TEST(Image, PngRoundTripIsBitExact) {
  fs::path file = scratch_dir("png") / "g.png";
  Image img = gradient(37, 21);
  img.write_image(file.string());
  Rgb8Image back = read_png(file.string());
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 21);
  EXPECT_EQ(back.rgb, img.to_rgb8().rgb);
}

TEST(Image, PngBytesAreTheFileWritePngWrites) {
  fs::path file = scratch_dir("png_bytes") / "g.png";
  Image img = gradient(19, 7);
  img.write_png(file.string());
  std::ifstream in(file, std::ios::binary);
  const std::vector<std::uint8_t> on_disk{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::vector<std::uint8_t> bytes = img.png_bytes();
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes[1], 'P');
  EXPECT_EQ(bytes, on_disk);
}

TEST(Image, PpmRoundTripIsBitExact) {
  fs::path file = scratch_dir("ppm") / "g.PPM";
  Image img = gradient(13, 40);
  img.write_image(file.string());
  Rgb8Image back = read_ppm(file.string());
  EXPECT_EQ(back.width, 13);
  EXPECT_EQ(back.height, 40);
  EXPECT_EQ(back.rgb, img.to_rgb8().rgb);
}

TEST(Image, UnknownExtensionNamesThePath) {
  Image img(1, 1);
  try {
    img.write_image("out.jpg");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'out.jpg'"), std::string::npos);
  }
}

TEST(Image, FailedWriteLeavesNoFileBehind) {
  fs::path dir = scratch_dir("fail");
  fs::create_directory(dir / "taken.png");  // rename onto a directory fails
  Image img(4, 4);
  EXPECT_THROW(img.write_png((dir / "taken.png").string()), std::runtime_error);
  EXPECT_THROW(img.write_ppm((dir / "missing" / "x.ppm").string()), std::runtime_error);
  std::size_t entries = 0;
  for ([[maybe_unused]] auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u);  // only the directory we made
}

TEST(Image, ReadersRejectOtherFormats) {
  fs::path file = scratch_dir("bad") / "x.ppm";
  Image(2, 2).write_png(file.string());  // PNG bytes under a .ppm name
  EXPECT_THROW(read_ppm(file.string()), std::runtime_error);
  Image(2, 2).write_ppm(file.string());
  EXPECT_THROW(read_png(file.string()), std::runtime_error);
}

}  // namespace
}  // namespace tracer
