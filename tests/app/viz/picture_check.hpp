// Test helpers for pictures drawn by the viz library: pixel lookups in a
// tracer::Image and checks on SVG and PDF documents that hold whatever the
// font on the machine: never exact text pixels.
#pragma once

#include <cstdint>
#include <set>
#include <string>

#include "app/viz/colour.hpp"
#include "tracer/image.hpp"

namespace viz::test {

// The byte colour of pixel (x, y).
Rgb8 pixel(const tracer::Rgb8Image& img, int x, int y);

// Whether two colours differ by at most `tolerance` in every channel.
bool near(Rgb8 a, Rgb8 b, int tolerance = 1);

// Pixels in [x0, x1) x [y0, y1) darker than `below` in every channel
// (text and lines on a white ground).
int dark_pixels(const tracer::Rgb8Image& img, int x0, int y0, int x1, int y1, int below = 128);

// Pixels in the rectangle that are grey (r == g == b) strictly between black
// and white: the anti-aliased edges of black text.
int intermediate_greys(const tracer::Rgb8Image& img, int x0, int y0, int x1, int y1);

// Every id="..." of an SVG document.
std::set<std::string> svg_ids(const std::string& svg);

// Every id an SVG document refers to by url(#...) or href="#...".
std::set<std::string> svg_references(const std::string& svg);

bool is_pdf(const std::string& bytes);

}  // namespace viz::test
