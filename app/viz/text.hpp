// Internal to the viz library: the one font every picture writes in (DejaVu
// Sans through cairo's toy text API, fontconfig's sans-serif if it is
// missing) and how wide a text is in it, for layouts decided before drawing.
// Invariants: text_width is what drawing the same text at the same font
// measures on any surface (metrics are not hinted); valid_utf8 returns
// valid UTF-8, so text given to cairo never puts a context in an error state.
#pragma once

#include <string>
#include <string_view>

namespace viz::detail {

struct Font {
  double size = 12;  // px (pt in PDF)
  bool bold = false;
};

// The advance of `text` in `font`, in px.
double text_width(std::string_view text, Font font);

// `text` with every byte that is not part of a valid UTF-8 sequence replaced by '?'.
std::string valid_utf8(std::string_view text);

// The text at the largest size in [min_size, font.size] that fits `room`
// px; too long even at min_size, it keeps its beginning and end around an
// ellipsis. Returns the text to draw and its font.
std::pair<std::string, Font> fit_text(std::string_view text, Font font, double min_size, double room);

}  // namespace viz::detail
