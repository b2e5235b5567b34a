// The rasteriser behind PNG plots; see canvas.hpp.
#include "app/viz/canvas.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <utility>

namespace viz::detail {
namespace {

struct Glyph {
  char ch;
  std::array<std::uint8_t, 7> rows;  // top to bottom; bit 4 is the leftmost column
};

constexpr Glyph font[] = {
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}},
    {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}},
    {'3', {0x1e, 0x01, 0x01, 0x0e, 0x01, 0x01, 0x1e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}},
    {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}},
    {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}},
    {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'A', {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'B', {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e}},
    {'C', {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e}},
    {'D', {0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c}},
    {'E', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f}},
    {'F', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10}},
    {'G', {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f}},
    {'H', {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'I', {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f}},
    {'M', {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'P', {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10}},
    {'Q', {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d}},
    {'R', {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11}},
    {'S', {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e}},
    {'T', {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a}},
    {'X', {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x0a, 0x04, 0x04, 0x04, 0x04}},
    {'Z', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}},
    {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}},
    {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}},
    {'&', {0x0c, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0d}},
    {'?', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f}},
};

constexpr int glyph_w = 5, glyph_h = 7, advance = 6;

const Glyph* glyph_of(char c) {
  const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : font)
    if (g.ch == up) return &g;
  for (const Glyph& g : font)
    if (g.ch == '?') return &g;
  return nullptr;
}

float to_unit(std::uint8_t v) { return static_cast<float>(v) / 255.0f; }

}  // namespace

Canvas::Canvas(int width, int height, Rgb8 background)
    : width_(std::max(width, 1)), height_(std::max(height, 1)),
      pixels_(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), background) {
  reset_clip();
}

void Canvas::put(int x, int y, Rgb8 c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  if (x < clip_.left || x >= clip_.right() || y < clip_.top || y >= clip_.bottom()) return;
  pixels_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)] = c;
}

void Canvas::fill_rect(const Rect& r, Rgb8 c) {
  const int x0 = static_cast<int>(std::floor(std::max(r.left, 0.0)));
  const int y0 = static_cast<int>(std::floor(std::max(r.top, 0.0)));
  const int x1 = static_cast<int>(std::ceil(std::min(r.right(), static_cast<double>(width_))));
  const int y1 = static_cast<int>(std::ceil(std::min(r.bottom(), static_cast<double>(height_))));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) put(x, y, c);
}

void Canvas::disk(Point centre, double radius, Rgb8 c) {
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y)) return;
  const double cx = std::clamp(centre.x, -1.0, width_ + 1.0), cy = std::clamp(centre.y, -1.0, height_ + 1.0);
  const int r = static_cast<int>(std::ceil(radius));
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= radius * radius + 0.25)
        put(static_cast<int>(std::lround(cx)) + dx, static_cast<int>(std::lround(cy)) + dy, c);
}

void Canvas::line(Point a, Point b, double width, Rgb8 c, double dash) {
  if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y)) return;
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  // Stamp a disk every half pixel: simple, and wide lines join without gaps.
  const int steps = static_cast<int>(std::min(std::ceil(len * 2.0), 1e6));
  for (int i = 0; i <= steps; ++i) {
    const double t = steps == 0 ? 0.0 : static_cast<double>(i) / steps;
    if (dash > 0 && std::fmod(t * len, 2 * dash) >= dash) continue;
    disk({a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t}, width / 2, c);
  }
}

double Canvas::text_width(std::string_view s, int scale) {
  return s.empty() ? 0.0 : static_cast<double>((advance * static_cast<int>(s.size()) - 1) * scale);
}

void Canvas::text(double x, double top, std::string_view s, int scale, Rgb8 c, Align align) {
  const double w = text_width(s, scale);
  double left = align == Align::left ? x : align == Align::centre ? x - w / 2 : x - w;
  for (char ch : s) {
    const Glyph* g = glyph_of(ch);
    for (int row = 0; g && ch != ' ' && row < glyph_h; ++row)
      for (int col = 0; col < glyph_w; ++col)
        if ((g->rows[static_cast<std::size_t>(row)] >> (glyph_w - 1 - col)) & 1)
          fill_rect({left + col * scale, top + row * scale, static_cast<double>(scale), static_cast<double>(scale)}, c);
    left += advance * scale;
  }
}

void Canvas::text_vertical(double cx, double cy, std::string_view s, int scale, Rgb8 c) {
  // Glyph column becomes height from the bottom; glyph row becomes x.
  double bottom = cy + text_width(s, scale) / 2;
  const double left = cx - glyph_h * scale / 2.0;
  for (char ch : s) {
    const Glyph* g = glyph_of(ch);
    for (int row = 0; g && ch != ' ' && row < glyph_h; ++row)
      for (int col = 0; col < glyph_w; ++col)
        if ((g->rows[static_cast<std::size_t>(row)] >> (glyph_w - 1 - col)) & 1)
          fill_rect({left + row * scale, bottom - (col + 1) * scale, static_cast<double>(scale),
                     static_cast<double>(scale)}, c);
    bottom -= advance * scale;
  }
}

tracer::Image Canvas::image() const {
  tracer::Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const Rgb8 p = pixels_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
      img.at(x, y) = {to_unit(p.r), to_unit(p.g), to_unit(p.b)};
    }
  return img;
}

}  // namespace viz::detail
