// The HTML report of a render: one self-contained page (no network: no
// external CSS, scripts or fonts) with statistics tables, inline SVG
// pictures and the images.
// Images are written as PNG files beside the HTML, named "<stem>-<n>.png"
// (n = 1, 2, ... in document order) and linked by file name, so the page
// references only files it wrote itself. All text is escaped; SVG figures
// are inserted as they are and must come from this library's *_svg functions.
// An image narrower than 256 px is shown enlarged by a whole factor, its
// pixels kept sharp; its PNG keeps the image's own size.
#pragma once

#include <filesystem>
#include <functional>
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
  std::vector<Section> sections{};
};

// Called with each file the writer has put in place, whole: the PNGs, then
// the page. A caller that must leave nothing after a failure removes what
// it was given (app::OutputFiles).
using FileTracker = std::function<void(const std::filesystem::path&)>;

// Writes the page to html_path (through a temporary file renamed into
// place) and its PNGs beside it. Returns every file written, the HTML last.
// Throws std::invalid_argument if an SvgFigure does not hold an <svg>
// document, std::runtime_error naming the path on an I/O failure.
// Where the page at html_path puts its n-th image (n from 1), beside it.
std::filesystem::path report_image_path(const std::filesystem::path& html_path, int n);

std::vector<std::filesystem::path> write_html_report(const std::filesystem::path& html_path, const Report& report,
                                                     const FileTracker& track);

}  // namespace viz
