// HTML report writer; see report.hpp for what the page may reference.
#include "app/viz/report.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "app/viz/svg.hpp"
#include "tracer/atomic_file.hpp"

namespace viz {
namespace {

namespace fs = std::filesystem;

constexpr const char* style = R"(body { font-family: sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
h1 { border-bottom: 2px solid #444; }
section { margin-bottom: 2em; }
table { border-collapse: collapse; margin: 1em 0; }
caption { font-weight: bold; text-align: left; padding-bottom: 0.3em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.6em; }
th { background: #f0f0f0; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1em 0; overflow-x: auto; }
figcaption { color: #555; font-size: 0.9em; }
img { image-rendering: pixelated; max-width: 100%; height: auto; }
.keyed { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
ol.key { list-style: none; margin: 0; padding: 0; display: grid; grid-template-columns: repeat(16, 2.6em);
         gap: 2px; font-size: 0.75em; }
ol.key li { text-align: center; border-radius: 2px; }
)";

// A file name as a relative URL: anything but unreserved characters is %-encoded.
std::string url_of(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~') {
      out += static_cast<char>(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      out += buf;
    }
  }
  return out;
}

// Images narrower than this are shown enlarged.
constexpr int min_display_width = 256;

// The whole factor that shows an image at least min_display_width wide.
int display_factor(int width) { return std::max(1, (min_display_width + width - 1) / std::max(width, 1)); }

// Black or white, whichever reads better on `background`.
std::string text_colour_on(Rgb8 background) {
  return 0.299 * background.r + 0.587 * background.g + 0.114 * background.b < 128.0 ? "#ffffff" : "#000000";
}

bool looks_numeric(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '+' && c != 'e' &&
        c != '%' && c != ',' && c != ' ')
      return false;
  return std::isdigit(static_cast<unsigned char>(s.front())) || s.front() == '-' || s.front() == '.';
}

void caption(std::string& out, const std::string& text) {
  if (!text.empty()) out += "<caption>" + escape_xml(text) + "</caption>\n";
}

class PageWriter {
 public:
  PageWriter(const fs::path& html, const FileTracker& track) : html_(html), track_(track) {}

  void operator()(const Paragraph& p) { out += "<p>" + escape_xml(p.text) + "</p>\n"; }

  void operator()(const KeyValueTable& t) {
    out += "<table class=\"stats\">\n";
    caption(out, t.caption);
    for (const auto& [k, v] : t.rows)
      out += "<tr><th>" + escape_xml(k) + "</th>" + cell(v) + "</tr>\n";
    out += "</table>\n";
  }

  void operator()(const Table& t) {
    out += "<table>\n";
    caption(out, t.caption);
    if (!t.header.empty()) {
      out += "<tr>";
      for (const std::string& h : t.header) out += "<th>" + escape_xml(h) + "</th>";
      out += "</tr>\n";
    }
    for (const auto& row : t.rows) {
      out += "<tr>";
      for (const std::string& c : row) out += cell(c);
      out += "</tr>\n";
    }
    out += "</table>\n";
  }

  void operator()(const SvgFigure& f) {
    if (f.svg.rfind("<svg", 0) != 0)
      throw std::invalid_argument("report figure '" + f.caption + "' is not an SVG document");
    out += "<figure>\n" + f.svg + figcaption(f.caption) + "</figure>\n";
  }

  void operator()(const ImageFigure& f) {
    const fs::path png = report_image_path(html_, ++images_);
    const std::string name = png.filename().string();
    f.image.write_png(png.string());  // whole or not at all
    track_(png);
    const int factor = display_factor(f.image.width());
    const std::string img = "<img src=\"" + escape_xml(url_of(name)) + "\" width=\"" +
                            std::to_string(factor * f.image.width()) + "\" height=\"" +
                            std::to_string(factor * f.image.height()) + "\" alt=\"" + escape_xml(f.caption) + "\"/>\n";
    out += "<figure>\n";
    if (f.key.empty()) {
      out += img;
    } else {
      out += "<div class=\"keyed\">\n" + img + "<ol class=\"key\">\n";
      for (const KeyEntry& k : f.key)
        out += "<li style=\"background:" + hex(k.colour) + ";color:" + text_colour_on(k.colour) + "\">" +
               escape_xml(k.label) + "</li>\n";
      out += "</ol>\n</div>\n";
    }
    out += figcaption(f.caption) + "</figure>\n";
  }

  std::string out;

 private:
  static std::string cell(const std::string& v) {
    return (looks_numeric(v) ? "<td class=\"num\">" : "<td>") + escape_xml(v) + "</td>";
  }
  static std::string figcaption(const std::string& text) {
    return text.empty() ? std::string{} : "<figcaption>" + escape_xml(text) + "</figcaption>\n";
  }

  const fs::path& html_;
  const FileTracker& track_;
  int images_ = 0;
};

// Writes the PNGs and then the page, each tracked once it is in place.
void write_page(const fs::path& html_path, const Report& report, const FileTracker& track) {
  PageWriter page(html_path, track);
  page.out = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>" +
             escape_xml(report.title) + "</title>\n<style>\n" + style + "</style>\n</head>\n<body>\n<h1>" +
             escape_xml(report.title) + "</h1>\n";
  for (const Section& s : report.sections) {
    page.out += "<section>\n<h2>" + escape_xml(s.heading) + "</h2>\n";
    for (const Block& b : s.blocks) std::visit(page, b);
    page.out += "</section>\n";
  }
  page.out += "</body>\n</html>\n";
  tracer::write_text_atomically(html_path.string(), page.out);
  track(html_path);
}

}  // namespace

fs::path report_image_path(const fs::path& html_path, int n) {
  return html_path.parent_path() / (html_path.stem().string() + "-" + std::to_string(n) + ".png");
}

std::vector<fs::path> write_html_report(const fs::path& html_path, const Report& report, const FileTracker& track) {
  // What was tracked is what was written, once the page is in place.
  std::vector<fs::path> written;
  write_page(html_path, report, [&](const fs::path& p) {
    track(p);
    written.push_back(p);
  });
  return written;
}

}  // namespace viz
