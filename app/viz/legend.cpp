// Captioned colour bars (see legend.hpp).
#include "app/viz/legend.hpp"

#include <cstdio>


namespace viz::detail {

void colour_bar(cairo_t* cr, double x, double y, Rgb8 (*scale)(double), const std::string& caption, double max) {
  set_colour(cr, {0, 0, 0});
  show_text(cr, x, y, caption, {12});
  gradient_bar(cr, x, y + 6, colour_bar_width, 10, scale);
  set_colour(cr, {0, 0, 0});
  show_text(cr, x, y + 30, "0", {11});
  // The bar's top is a measured maximum, not a tick: three significant digits.
  char top[32];
  std::snprintf(top, sizeof top, "%.3g", max);
  show_text(cr, x + colour_bar_width, y + 30, top, {11}, Align::right);
}

}  // namespace viz::detail
