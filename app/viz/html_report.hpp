// The HTML report of a render or a sweep: one page that stands alone, with
// no reference to anything outside it (no network, no other file: styles
// inline, SVG figures inline, images as PNG data: URLs), so it can be mailed,
// archived or opened from anywhere.
// Invariants: all text is escaped; SVG figures are inserted as they are and
// must come from this library's *_svg functions; an image narrower than
// 256 px is shown enlarged by a whole factor, its pixels kept sharp, and is
// embedded at its own size.
#pragma once

#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "app/viz/colour.hpp"
#include "tracer/image.hpp"

namespace viz {

struct Paragraph {
  std::string text{};
};

struct KeyValueTable {
  std::string caption{};
  std::vector<std::pair<std::string, std::string>> rows{};
};

struct Table {
  std::string caption{};
  std::vector<std::string> header{};
  std::vector<std::vector<std::string>> rows{};  // cells that read as numbers are right-aligned
};

struct SvgFigure {
  std::string caption{};
  std::string svg{};  // a document from plot_svg, plots_svg or machine_svg
};

// One entry of an image's colour key: what a colour in the image stands for.
struct KeyEntry {
  std::string label{};
  Rgb8 colour{};
};

struct ImageFigure {
  std::string caption{};
  tracer::Image image{};
  std::vector<KeyEntry> key{};  // shown beside the image as numbered swatches; empty: none
};

using Block = std::variant<Paragraph, KeyValueTable, Table, SvgFigure, ImageFigure>;

struct Section {
  std::string heading{};
  std::vector<Block> blocks{};
};

struct Report {
  std::string title{};
  std::string version{};                    // of the program that made the page; empty: not shown
  std::vector<std::string> command_line{};  // as typed, shown shell-quoted; empty: not shown
  std::vector<Section> sections{};
};

// The page. Throws std::invalid_argument if an SvgFigure does not hold an
// <svg> document, std::runtime_error if an image cannot be encoded.
std::string html_report(const Report& report);

// The image as a data: URL of its PNG bytes, for pages that stand alone.
std::string png_data_url(const tracer::Image& image);

// Words as a POSIX shell would need them typed: each word that holds
// anything but letters, digits and -_./=:,+@% in single quotes.
std::string shell_quoted(const std::vector<std::string>& words);

}  // namespace viz
