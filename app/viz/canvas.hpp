// Internal to the viz library: a tiny 8-bit RGB rasteriser (thick and dashed
// lines, disks, rectangles, a built-in 5x7 bitmap font) for PNG pictures.
// Invariants: every drawing call clips to the canvas and to the current clip
// rectangle, so any coordinates (even far outside) are safe; no antialiasing,
// so the output is exact and reproducible.
#pragma once

#include <string_view>
#include <vector>

#include "app/viz/colour.hpp"
#include "app/viz/plot_geometry.hpp"
#include "tracer/image.hpp"

namespace viz::detail {

enum class Align { left, centre, right };

class Canvas {
 public:
  Canvas(int width, int height, Rgb8 background);

  void set_clip(const Rect& r) { clip_ = r; }
  void reset_clip() { clip_ = {0, 0, static_cast<double>(width_), static_cast<double>(height_)}; }

  void fill_rect(const Rect& r, Rgb8 c);
  // `dash` > 0: alternate `dash` pixels drawn and `dash` pixels skipped.
  void line(Point a, Point b, double width, Rgb8 c, double dash = 0);
  void disk(Point centre, double radius, Rgb8 c);
  // Text in the 5x7 font magnified by `scale`; `top` is the top of the glyphs.
  // Lower-case letters are drawn as capitals, unknown characters as '?'.
  void text(double x, double top, std::string_view s, int scale, Rgb8 c, Align align = Align::left);
  // The same, rotated a quarter turn anticlockwise (reads bottom to top), centred on (cx, cy).
  void text_vertical(double cx, double cy, std::string_view s, int scale, Rgb8 c);
  static double text_width(std::string_view s, int scale);

  tracer::Image image() const;

 private:
  void put(int x, int y, Rgb8 c);

  int width_, height_;
  std::vector<Rgb8> pixels_;
  Rect clip_;
};

}  // namespace viz::detail
