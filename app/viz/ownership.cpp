// Pixel-ownership images, and their picture with a key; see ownership.hpp.
#include "app/viz/ownership.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/viz/colour.hpp"
#include "app/viz/drawing.hpp"

namespace viz {
namespace {

void check_size(int width, int height, std::size_t owners) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("ownership image: size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not positive");
  if (owners != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw std::invalid_argument("ownership image: " + std::to_string(owners) + " owners for " +
                                std::to_string(width) + "x" + std::to_string(height) + " pixels");
}

tracer::Color colour_for(std::uint16_t node) {
  const Rgb8 c = node_colour(node);
  return {c.r / 255.0f, c.g / 255.0f, c.b / 255.0f};
}

constexpr int margin = 8;
constexpr int min_shown_width = 256;
constexpr int max_side = 16384;
constexpr std::size_t compact_above = 256;     // entries; more: the compact key
constexpr int swatch = 12, row_step = 16;      // the labelled key
constexpr int small_swatch = 8;                // the compact key: 32 a row, 64 over 1024 entries
constexpr double key_font = 11;

struct KeyLayout {
  int left = 0, top = 0;  // of the key's first cell
  int columns = 1, rows = 1;
  int cell_w = 0, cell_h = 0;
  int label_w = 0;  // compact key: the column of row labels
  bool compact = false;
  int width() const { return label_w + columns * cell_w; }
  int height() const { return rows * cell_h; }
};

int widest_label(const std::vector<KeyEntry>& key) {
  double w = 0;
  for (const KeyEntry& k : key) w = std::max(w, detail::text_width(k.label, {key_font}));
  return static_cast<int>(std::ceil(w));
}

// Beside the image in up to four columns, else under it; compact for many entries.
KeyLayout key_layout(const std::vector<KeyEntry>& key, int shown_w, int shown_h) {
  KeyLayout k;
  const int n = static_cast<int>(key.size());
  if (key.size() > compact_above) {
    k.compact = true;
    k.cell_w = small_swatch + 1;  // swatches a pixel apart, rows two apart: the labels need the room
    k.cell_h = small_swatch + 2;
    k.label_w = widest_label(key) + 4;
    k.columns = key.size() > 1024 ? 64 : 32;
    k.rows = (n + k.columns - 1) / k.columns;
    k.left = margin;
    k.top = margin + shown_h + margin;
    return k;
  }
  k.cell_w = swatch + 4 + widest_label(key) + 10;
  k.cell_h = row_step;
  const int rows_beside = std::max(1, shown_h / row_step);
  const int columns_beside = (n + rows_beside - 1) / rows_beside;
  if (columns_beside <= 4) {
    k.rows = std::min(n, rows_beside);
    k.columns = columns_beside;
    k.left = margin + shown_w + 2 * margin;
    k.top = margin;
  } else {
    k.columns = std::max(1, std::max(shown_w, 400) / k.cell_w);
    k.rows = (n + k.columns - 1) / k.columns;
    k.left = margin;
    k.top = margin + shown_h + margin;
  }
  return k;
}

void draw_key(cairo_t* cr, const std::vector<KeyEntry>& key, const KeyLayout& k) {
  for (std::size_t i = 0; i < key.size(); ++i) {
    const int index = static_cast<int>(i);
    // The labelled key fills column by column, the compact one row by row.
    const int column = k.compact ? index % k.columns : index / k.rows;
    const int row = k.compact ? index / k.columns : index % k.rows;
    const int x = k.left + k.label_w + column * k.cell_w, y = k.top + row * k.cell_h;
    detail::set_colour(cr, key[i].colour);
    cairo_rectangle(cr, x, y, k.compact ? small_swatch : swatch, k.compact ? small_swatch : swatch);
    cairo_fill(cr);
    detail::set_colour(cr, {0, 0, 0});
    if (!k.compact)
      detail::show_text(cr, x + swatch + 4, y + swatch - 2, key[i].label, {key_font});
    else if (column == 0)
      detail::show_text(cr, k.left + k.label_w - 4, y + small_swatch, key[i].label, {small_swatch + 1.0},
                        detail::Align::right);
  }
}

// The image as a cairo surface of its bytes, for painting enlarged.
std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface_of(const tracer::Image& img) {
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> s(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, img.width(), img.height()), cairo_surface_destroy);
  detail::check(cairo_surface_status(s.get()), "ownership picture");
  cairo_surface_flush(s.get());
  unsigned char* data = cairo_image_surface_get_data(s.get());
  const int stride = cairo_image_surface_get_stride(s.get());
  const tracer::Rgb8Image bytes = img.to_rgb8();
  for (int y = 0; y < img.height(); ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < img.width(); ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width()) + x) * 3;
      row[x] = (std::uint32_t{bytes.rgb[i]} << 16) | (std::uint32_t{bytes.rgb[i + 1]} << 8) | bytes.rgb[i + 2];
    }
  }
  cairo_surface_mark_dirty(s.get());
  return s;
}

}  // namespace

tracer::Image ownership_image(int width, int height, const std::vector<std::uint16_t>& owners) {
  check_size(width, height, owners.size());
  tracer::Image img(width, height);
  std::size_t i = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) img.at(x, y) = colour_for(owners[i++]);
  return img;
}

tracer::Image ownership_overlay(const tracer::Image& rendered, const std::vector<std::uint16_t>& owners,
                                float weight) {
  check_size(rendered.width(), rendered.height(), owners.size());
  weight = std::clamp(weight, 0.0f, 1.0f);
  tracer::Image img(rendered.width(), rendered.height());
  std::size_t i = 0;
  for (int y = 0; y < rendered.height(); ++y)
    for (int x = 0; x < rendered.width(); ++x)
      img.at(x, y) = rendered.at(x, y) * (1.0f - weight) + colour_for(owners[i++]) * weight;
  return img;
}

tracer::Image ownership_picture(const tracer::Image& ownership, const std::vector<KeyEntry>& key) {
  if (ownership.width() <= 0 || ownership.height() <= 0)
    throw std::invalid_argument("ownership picture: the image is empty");
  const int factor = std::max(1, (min_shown_width + ownership.width() - 1) / ownership.width());
  const long long shown_w = static_cast<long long>(factor) * ownership.width();
  const long long shown_h = static_cast<long long>(factor) * ownership.height();
  if (shown_w > max_side || shown_h > max_side)
    throw std::invalid_argument("ownership picture: a " + std::to_string(ownership.width()) + "x" +
                                std::to_string(ownership.height()) + " image is over " + std::to_string(max_side) +
                                " px a side");
  const KeyLayout k = key_layout(key, static_cast<int>(shown_w), static_cast<int>(shown_h));
  const long long width = std::max(margin + shown_w, key.empty() ? 0LL : k.left + k.width()) + margin;
  const long long height = std::max(margin + shown_h, key.empty() ? 0LL : k.top + k.height()) + margin;
  if (width > max_side || height > max_side)
    throw std::invalid_argument("ownership picture: " + std::to_string(width) + "x" + std::to_string(height) +
                                " px with its key, over " + std::to_string(max_side) + " a side");
  const auto source = surface_of(ownership);
  return detail::draw_image("ownership picture", static_cast<int>(width), static_cast<int>(height), [&](cairo_t* cr) {
    cairo_save(cr);
    cairo_translate(cr, margin, margin);
    cairo_scale(cr, factor, factor);
    cairo_set_source_surface(cr, source.get(), 0, 0);
    cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
    cairo_rectangle(cr, 0, 0, ownership.width(), ownership.height());
    cairo_fill(cr);
    cairo_restore(cr);
    draw_key(cr, key, k);
  });
}

}  // namespace viz
