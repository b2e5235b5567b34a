// Internal to the viz library: a picture is a function that draws on a
// cairo context in px, drawn once and written by one of three surfaces: an
// image surface copied into a tracer::Image (for PNG), an SVG surface
// (returned as text ready to inline in HTML, see svg.hpp) or a PDF surface.
// Invariants: every surface starts white; a cairo failure, on the context or
// the surface, throws std::runtime_error naming what was being drawn; all
// text goes through show_text in the font of text.hpp (in SVG, each glyph
// is drawn once and <use>d by reference within the document).
#pragma once

#include <cairo.h>

#include <functional>
#include <string>
#include <string_view>

#include "app/viz/colour.hpp"
#include "app/viz/text.hpp"
#include "tracer/image.hpp"

namespace viz::detail {

using Draw = std::function<void(cairo_t*)>;

// Throws std::runtime_error("<what>: <cairo's message>") unless status is success.
void check(cairo_status_t status, const char* what);

// `what` names the picture in error messages. Sizes are px; the image
// surface rounds nothing: width and height are its pixels.
tracer::Image draw_image(const char* what, int width, int height, const Draw& draw);
std::string draw_svg(const char* what, double width, double height, const Draw& draw);
std::string draw_pdf(const char* what, double width, double height, const Draw& draw);

void set_colour(cairo_t* cr, Rgb8 c, double alpha = 1.0);

enum class Align { left, centre, right };

// Draws `text` with its baseline at y, starting at, centred on or ending at x.
void show_text(cairo_t* cr, double x, double y, std::string_view text, Font font, Align align = Align::left);
// The same, turned a quarter anticlockwise (reads bottom to top), centred on (x, y).
void show_text_upwards(cairo_t* cr, double x, double y, std::string_view text, Font font);

// A horizontal bar of `scale` from 0 (left) to 1 (right), outlined.
void gradient_bar(cairo_t* cr, double x, double y, double width, double height, Rgb8 (*scale)(double));

}  // namespace viz::detail
