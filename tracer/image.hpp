// Rendered images: linear float RGB in memory, 8-bit RGB on disk (no gamma).
// to_rgb8 is the single conversion to bytes (clamp to [0,1], NaN -> 0, then
// round-half-up of v*255), so two renders compare bit-exactly on disk.
// Writers go to a temporary file beside the target and rename it into place:
// an interrupted or failed write never leaves a partial output file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tracer/vec.hpp"

namespace tracer {

struct Rgb8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major from the top row, 3 bytes per pixel
};

class Image {
 public:
  Image() = default;
  Image(int width, int height);  // black; throws std::invalid_argument if not positive
  // Takes `pixels` (row-major from the top row) as the image's own, without a
  // copy; std::invalid_argument unless the size is positive and they fill it.
  Image(int width, int height, std::vector<Color> pixels);

  int width() const { return width_; }
  int height() const { return height_; }
  // (0,0) is the top-left pixel.
  Color& at(int x, int y) { return pixels_[index(x, y)]; }
  const Color& at(int x, int y) const { return pixels_[index(x, y)]; }
  const std::vector<Color>& pixels() const { return pixels_; }

  Rgb8Image to_rgb8() const;

  // The PNG file's bytes, for embedding (e.g. a data: URL); std::runtime_error
  // if libpng cannot encode the image.
  std::vector<std::uint8_t> png_bytes() const;

  // Throw std::runtime_error naming the path on any I/O failure.
  void write_png(const std::string& path) const;
  void write_ppm(const std::string& path) const;
  // By extension, case-insensitive: ".png" or ".ppm"; anything else throws
  // std::invalid_argument naming the path.
  void write_image(const std::string& path) const;

 private:
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<Color> pixels_;
};

std::uint8_t to_byte(float linear);

// Readers, mainly for tests; they throw std::runtime_error naming the path.
Rgb8Image read_png(const std::string& path);
Rgb8Image read_ppm(const std::string& path);

// The extension of the file name in `path`, lower case, with its dot ("" if none).
std::string lower_extension(const std::string& path);

}  // namespace tracer
