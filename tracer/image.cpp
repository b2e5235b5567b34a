// Image storage, the one float->byte conversion, PNG (libpng's simplified
// API, which needs no setjmp) and binary PPM writers and readers. Writes go
// through a temporary file in the target's directory, renamed on success.
#include "tracer/image.hpp"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "tracer/atomic_file.hpp"

namespace tracer {
namespace {

std::runtime_error io_error(const std::string& path, const std::string& what) {
  return std::runtime_error(path + ": " + what);
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// width x height; std::invalid_argument unless both are positive.
std::size_t pixel_count(int width, int height) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("image size must be positive");
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

// Reads the next PPM header field (a token), skipping blanks and # comments.
bool ppm_header_int(std::FILE* f, int& value) {
  int c = std::fgetc(f);
  while (c == '#' || std::isspace(c)) {
    if (c == '#') while (c != '\n' && c != EOF) c = std::fgetc(f);
    c = std::fgetc(f);
  }
  if (!std::isdigit(c)) return false;
  long long v = 0;
  for (; std::isdigit(c) && v <= 1'000'000; c = std::fgetc(f)) v = v * 10 + (c - '0');
  value = static_cast<int>(std::min<long long>(v, 1'000'001));
  return std::isspace(c);  // exactly one blank ends the header's last field
}

}  // namespace

Image::Image(int width, int height) : width_(width), height_(height), pixels_(pixel_count(width, height)) {}

Image::Image(int width, int height, std::vector<Color> pixels)
    : width_(width), height_(height), pixels_(std::move(pixels)) {
  if (pixels_.size() != pixel_count(width, height))
    throw std::invalid_argument(std::to_string(pixels_.size()) + " pixels for a " + std::to_string(width) + "x" +
                                std::to_string(height) + " image");
}

std::uint8_t to_byte(float linear) {
  float v = std::isnan(linear) ? 0.0f : std::clamp(linear, 0.0f, 1.0f);
  return static_cast<std::uint8_t>(std::floor(v * 255.0f + 0.5f));
}

Rgb8Image Image::to_rgb8() const {
  Rgb8Image out{width_, height_, {}};
  out.rgb.reserve(pixels_.size() * 3);
  for (const Color& c : pixels_) {
    out.rgb.push_back(to_byte(c.r));
    out.rgb.push_back(to_byte(c.g));
    out.rgb.push_back(to_byte(c.b));
  }
  return out;
}

void Image::write_png(const std::string& path) const {
  Rgb8Image bytes = to_rgb8();
  write_atomically(path, [&](std::FILE* file) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(width_);
    png.height = static_cast<png_uint_32>(height_);
    png.format = PNG_FORMAT_RGB;
    bool ok = png_image_write_to_stdio(&png, file, 0, bytes.rgb.data(), 0, nullptr) != 0;
    png_image_free(&png);
    return ok;
  });
}

std::vector<std::uint8_t> Image::png_bytes() const {
  Rgb8Image bytes = to_rgb8();
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(width_);
  png.height = static_cast<png_uint_32>(height_);
  png.format = PNG_FORMAT_RGB;
  // libpng's two-call protocol: the first call (no buffer) sizes, the second writes.
  png_alloc_size_t size = 0;
  std::vector<std::uint8_t> out;
  bool ok = png_image_write_to_memory(&png, nullptr, &size, 0, bytes.rgb.data(), 0, nullptr) != 0;
  if (ok) {
    out.resize(size);
    ok = png_image_write_to_memory(&png, out.data(), &size, 0, bytes.rgb.data(), 0, nullptr) != 0;
    out.resize(size);
  }
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok)
    throw std::runtime_error("cannot encode a " + std::to_string(width_) + "x" + std::to_string(height_) +
                             " PNG: " + message);
  return out;
}

void Image::write_ppm(const std::string& path) const {
  Rgb8Image bytes = to_rgb8();
  write_atomically(path, [&](std::FILE* file) {
    std::string header = "P6\n" + std::to_string(width_) + " " + std::to_string(height_) + "\n255\n";
    return std::fwrite(header.data(), 1, header.size(), file) == header.size() &&
           std::fwrite(bytes.rgb.data(), 1, bytes.rgb.size(), file) == bytes.rgb.size();
  });
}

std::string lower_extension(const std::string& path) {
  auto slash = path.find_last_of('/');
  auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void Image::write_image(const std::string& path) const {
  std::string ext = lower_extension(path);
  if (ext == ".png") return write_png(path);
  if (ext == ".ppm") return write_ppm(path);
  throw std::invalid_argument("cannot write image '" + path + "': unknown extension (use .png or .ppm)");
}

Rgb8Image read_png(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw io_error(path, std::string("cannot read PNG: ") + png.message);
  png.format = PNG_FORMAT_RGB;
  Rgb8Image out{static_cast<int>(png.width), static_cast<int>(png.height), {}};
  out.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    throw io_error(path, "cannot decode PNG: " + message);
  }
  return out;
}

Rgb8Image read_ppm(const std::string& path) {
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) throw io_error(path, std::string("cannot open: ") + std::strerror(errno));
  char magic[2] = {};
  Rgb8Image out;
  int maxval = 0;
  if (std::fread(magic, 1, 2, file.get()) != 2 || magic[0] != 'P' || magic[1] != '6' ||
      !ppm_header_int(file.get(), out.width) || !ppm_header_int(file.get(), out.height) ||
      !ppm_header_int(file.get(), maxval) || maxval != 255 || out.width < 1 || out.height < 1 ||
      static_cast<long long>(out.width) * out.height > (1LL << 28))
    throw io_error(path, "not a binary PPM (P6, maxval 255)");
  out.rgb.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3);
  if (std::fread(out.rgb.data(), 1, out.rgb.size(), file.get()) != out.rgb.size())
    throw io_error(path, "truncated PPM pixel data");
  return out;
}

}  // namespace tracer
