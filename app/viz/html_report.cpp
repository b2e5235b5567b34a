// HTML report writer; see html_report.hpp for why the page references nothing outside it.
#include "app/viz/html_report.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <stdexcept>

#include "app/viz/svg.hpp"

namespace viz {
namespace {

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
p.made { color: #555; }
p.made code { background: #f4f4f4; padding: 0.1em 0.3em; overflow-wrap: anywhere; }
img { image-rendering: pixelated; max-width: 100%; height: auto; }
.keyed { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
ol.key { list-style: none; margin: 0; padding: 0; display: grid; grid-template-columns: repeat(16, 2.6em);
         gap: 2px; font-size: 0.75em; }
ol.key li { text-align: center; border-radius: 2px; }
)";

// RFC 4648 base64 with padding, for data: URLs. Written here rather than
// taken from a library: Debian's Boost keeps its encoder in a detail
// namespace, and these dozen lines are the whole of it.
std::string base64(const std::vector<std::uint8_t>& bytes) {
  static constexpr char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = std::uint32_t(bytes[i]) << 16;
    if (n > 1) v |= std::uint32_t(bytes[i + 1]) << 8;
    if (n > 2) v |= bytes[i + 2];
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? digits[(v >> (18 - 6 * k)) & 63] : '=';
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
    const int factor = display_factor(f.image.width());
    const std::string img = "<img src=\"data:image/png;base64," + base64(f.image.png_bytes()) + "\" width=\"" +
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
};

}  // namespace

std::string html_report(const Report& report) {
  PageWriter page;
  page.out = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>" +
             escape_xml(report.title) + "</title>\n<style>\n" + style + "</style>\n</head>\n<body>\n<h1>" +
             escape_xml(report.title) + "</h1>\n";
  if (!report.version.empty() || !report.command_line.empty()) {
    page.out += "<p class=\"made\">";
    if (!report.version.empty()) page.out += "Made by " + escape_xml(report.version);
    if (!report.command_line.empty())
      page.out += std::string(report.version.empty() ? "Made" : "") + " with <code>" +
                  escape_xml(shell_quoted(report.command_line)) + "</code>";
    page.out += "</p>\n";
  }
  for (const Section& s : report.sections) {
    page.out += "<section>\n<h2>" + escape_xml(s.heading) + "</h2>\n";
    for (const Block& b : s.blocks) std::visit(page, b);
    page.out += "</section>\n";
  }
  page.out += "</body>\n</html>\n";
  return std::move(page.out);
}

std::string png_data_url(const tracer::Image& image) { return "data:image/png;base64," + base64(image.png_bytes()); }

std::string shell_quoted(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    if (!out.empty()) out += ' ';
    const bool plain = !w.empty() && std::all_of(w.begin(), w.end(), [](unsigned char c) {
      return std::isalnum(c) || std::string_view("-_./=:,+@%").find(char(c)) != std::string_view::npos;
    });
    if (plain) {
      out += w;
      continue;
    }
    out += '\'';
    for (char c : w) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += '\'';
  }
  return out;
}

}  // namespace viz
