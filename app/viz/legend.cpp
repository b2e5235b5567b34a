// Captioned colour bars (see legend.hpp).
#include "app/viz/legend.hpp"

#include "app/viz/ticks.hpp"

namespace viz::detail {

void colour_bar(cairo_t* cr, double x, double y, Rgb8 (*scale)(double), const std::string& caption, double max) {
  set_colour(cr, {0, 0, 0});
  show_text(cr, x, y, caption, {12});
  gradient_bar(cr, x, y + 6, colour_bar_width, 10, scale);
  set_colour(cr, {0, 0, 0});
  show_text(cr, x, y + 30, "0", {11});
  show_text(cr, x + colour_bar_width, y + 30, format_number(max), {11}, Align::right);
}

}  // namespace viz::detail
