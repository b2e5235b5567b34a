// Cairo surfaces, text and colour for the viz pictures; see drawing.hpp and text.hpp.
#include "app/viz/drawing.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "app/viz/svg.hpp"

namespace viz::detail {
namespace {

constexpr const char* font_family = "DejaVu Sans";

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* cr) const { cairo_destroy(cr); }
};
using Surface = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using Context = std::unique_ptr<cairo_t, ContextDeleter>;

// Unhinted metrics and greyscale antialiasing: text measures the same on
// every surface and PNG text has smooth edges.
void set_font_options(cairo_t* cr) {
  cairo_font_options_t* options = cairo_font_options_create();
  cairo_font_options_set_antialias(options, CAIRO_ANTIALIAS_GRAY);
  cairo_font_options_set_hint_style(options, CAIRO_HINT_STYLE_NONE);
  cairo_font_options_set_hint_metrics(options, CAIRO_HINT_METRICS_OFF);
  cairo_set_font_options(cr, options);
  cairo_font_options_destroy(options);
}

void select_font(cairo_t* cr, Font font) {
  cairo_select_font_face(cr, font_family, CAIRO_FONT_SLANT_NORMAL,
                         font.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, font.size);
}

// Draws on `surface` (white first) and checks both for errors. A stream
// surface is finished, so that it has written everything; an image surface
// is only flushed, as finishing it would free its pixels.
void draw_on(const char* what, cairo_surface_t* surface, const Draw& draw) {
  check(cairo_surface_status(surface), what);
  {
    Context cr(cairo_create(surface));
    check(cairo_status(cr.get()), what);
    set_font_options(cr.get());
    cairo_set_source_rgb(cr.get(), 1, 1, 1);
    cairo_paint(cr.get());
    draw(cr.get());
    check(cairo_status(cr.get()), what);
  }
  if (cairo_surface_get_type(surface) == CAIRO_SURFACE_TYPE_IMAGE)
    cairo_surface_flush(surface);
  else
    cairo_surface_finish(surface);
  check(cairo_surface_status(surface), what);
}

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Length of the valid UTF-8 sequence starting at s[i], or 0.
std::size_t utf8_sequence(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  // Lead byte: the sequence's length, its payload bits, and the least code
  // point that needs that length (shorter encodings are invalid).
  struct Lead {
    unsigned char mask, value, payload;
    std::size_t length;
    std::uint32_t min;
  };
  static constexpr Lead leads[] = {
      {0xE0, 0xC0, 0x1F, 2, 0x80}, {0xF0, 0xE0, 0x0F, 3, 0x800}, {0xF8, 0xF0, 0x07, 4, 0x10000}};
  const Lead* lead = nullptr;
  for (const Lead& l : leads)
    if ((c & l.mask) == l.value) lead = &l;
  if (lead == nullptr) return 0;
  const std::size_t n = lead->length;
  const std::uint32_t min = lead->min;
  std::uint32_t code = c & lead->payload;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (b(i + k) & 0x3F);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return n;
}

// Byte offsets where the characters of valid UTF-8 `s` start, and s.size() last.
std::vector<std::size_t> char_starts(const std::string& s) {
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < s.size(); ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) starts.push_back(i);
  starts.push_back(s.size());
  return starts;
}

}  // namespace

void check(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string(what) + ": cairo: " + cairo_status_to_string(status));
}

tracer::Image draw_image(const char* what, int width, int height, const Draw& draw) {
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height));
  draw_on(what, surface.get(), draw);
  const unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  if (data == nullptr) throw std::runtime_error(std::string(what) + ": cairo gave no pixels");
  std::vector<tracer::Color> pixels;
  pixels.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < width; ++x) {
      const std::uint32_t p = row[x];  // 0x00RRGGBB in native byte order
      pixels.push_back({static_cast<float>((p >> 16) & 0xFF) / 255.0f, static_cast<float>((p >> 8) & 0xFF) / 255.0f,
                        static_cast<float>(p & 0xFF) / 255.0f});
    }
  }
  return tracer::Image(width, height, std::move(pixels));
}

std::string draw_svg(const char* what, double width, double height, const Draw& draw) {
  std::string out;
  Surface surface(cairo_svg_surface_create_for_stream(append, &out, width, height));
  check(cairo_surface_status(surface.get()), what);
  cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
  draw_on(what, surface.get(), draw);
  return inlinable_svg(out);
}

std::string draw_pdf(const char* what, double width, double height, const Draw& draw) {
  std::string out;
  Surface surface(cairo_pdf_surface_create_for_stream(append, &out, width, height));
  draw_on(what, surface.get(), draw);
  return out;
}

void set_colour(cairo_t* cr, Rgb8 c, double alpha) {
  cairo_set_source_rgba(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0, alpha);
}

void show_text(cairo_t* cr, double x, double y, std::string_view text, Font font, Align align) {
  if (text.empty()) return;
  const std::string s = valid_utf8(text);
  select_font(cr, font);
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  if (align == Align::centre) x -= e.x_advance / 2;
  if (align == Align::right) x -= e.x_advance;
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
  cairo_new_path(cr);
}

void show_text_upwards(cairo_t* cr, double x, double y, std::string_view text, Font font) {
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_rotate(cr, -1.5707963267948966);
  show_text(cr, 0, font.size * 0.35, text, font, Align::centre);
  cairo_restore(cr);
}

void gradient_bar(cairo_t* cr, double x, double y, double width, double height, Rgb8 (*scale)(double)) {
  cairo_pattern_t* p = cairo_pattern_create_linear(x, 0, x + width, 0);
  for (int i = 0; i <= 10; ++i) {
    const Rgb8 c = scale(i / 10.0);
    cairo_pattern_add_color_stop_rgb(p, i / 10.0, c.r / 255.0, c.g / 255.0, c.b / 255.0);
  }
  cairo_rectangle(cr, x, y, width, height);
  cairo_set_source(cr, p);
  cairo_fill_preserve(cr);
  cairo_pattern_destroy(p);
  set_colour(cr, {51, 51, 51});
  cairo_set_line_width(cr, 1);
  cairo_stroke(cr);
}

double text_width(std::string_view text, Font font) {
  if (text.empty()) return 0;
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_A8, 1, 1));
  Context cr(cairo_create(surface.get()));
  set_font_options(cr.get());
  select_font(cr.get(), font);
  const std::string s = valid_utf8(text);
  cairo_text_extents_t e;
  cairo_text_extents(cr.get(), s.c_str(), &e);
  check(cairo_status(cr.get()), "measuring text");
  return e.x_advance;
}

std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence(text, i);
    // NUL would end the text early for cairo.
    if (n == 0 || text[i] == '\0') {
      out += '?';
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::pair<std::string, Font> fit_text(std::string_view text, Font font, double min_size, double room) {
  const std::string s = valid_utf8(text);
  const double full = text_width(s, font);
  if (full <= room) return {s, font};
  // Unhinted text scales linearly with its size; rounding the size down keeps it within room.
  Font shrunk = font;
  shrunk.size = std::max(min_size, std::floor(font.size * room / full * 100) / 100);
  if (text_width(s, shrunk) <= room) return {s, shrunk};
  const std::vector<std::size_t> starts = char_starts(s);
  const std::size_t chars = starts.size() - 1;
  const auto shortened = [&](std::size_t keep) {
    const std::size_t tail = keep / 2, head = keep - tail;
    return s.substr(0, starts[head]) + "\u2026" + s.substr(starts[chars - tail]);
  };
  // The most characters that still fit around the ellipsis.
  std::size_t lo = 0, hi = chars;
  while (lo < hi) {
    const std::size_t mid = (lo + hi + 1) / 2;
    if (text_width(shortened(mid), shrunk) <= room)
      lo = mid;
    else
      hi = mid - 1;
  }
  return {shortened(lo), shrunk};
}

}  // namespace viz::detail
