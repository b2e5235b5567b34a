// Pixel and document checks for viz pictures; see picture_check.hpp.
#include "picture_check.hpp"

#include <algorithm>
#include <cstdlib>

namespace viz::test {
namespace {

// The names following every occurrence of `opening`, up to `closing`.
std::set<std::string> names_after(const std::string& text, const std::string& opening, char closing) {
  std::set<std::string> out;
  for (std::size_t at = text.find(opening); at != std::string::npos; at = text.find(opening, at + 1)) {
    const std::size_t start = at + opening.size(), end = text.find(closing, start);
    if (end != std::string::npos) out.insert(text.substr(start, end - start));
  }
  return out;
}

}  // namespace

Rgb8 pixel(const tracer::Rgb8Image& img, int x, int y) {
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + x) * 3;
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

bool near(Rgb8 a, Rgb8 b, int tolerance) {
  return std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance && std::abs(a.b - b.b) <= tolerance;
}

int dark_pixels(const tracer::Rgb8Image& img, int x0, int y0, int x1, int y1, int below) {
  int n = 0;
  for (int y = std::max(0, y0); y < std::min(img.height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width, x1); ++x) {
      const Rgb8 p = pixel(img, x, y);
      n += p.r < below && p.g < below && p.b < below;
    }
  return n;
}

int intermediate_greys(const tracer::Rgb8Image& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = std::max(0, y0); y < std::min(img.height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width, x1); ++x) {
      const Rgb8 p = pixel(img, x, y);
      n += p.r == p.g && p.g == p.b && p.r > 0 && p.r < 255;
    }
  return n;
}

std::set<std::string> svg_ids(const std::string& svg) { return names_after(svg, " id=\"", '"'); }

std::set<std::string> svg_references(const std::string& svg) {
  std::set<std::string> refs = names_after(svg, "url(#", ')');
  for (const std::string& r : names_after(svg, "href=\"#", '"')) refs.insert(r);
  return refs;
}

bool is_pdf(const std::string& bytes) {
  return bytes.rfind("%PDF-", 0) == 0 && bytes.find("%%EOF") != std::string::npos;
}

}  // namespace viz::test
