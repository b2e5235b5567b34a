// SVG text building; see svg.hpp for the invariants.
#include "app/viz/svg.hpp"

#include <cmath>
#include <cstdio>

namespace viz {

std::string escape_xml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string num(double value) {
  if (!std::isfinite(value)) return "0";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.2f", value);
  std::string s = buf;
  // Trim trailing zeros (and a bare point) to keep files small.
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

SvgDocument::SvgDocument(double width, double height) {
  out_ += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(width) + "\" height=\"" +
          num(height) + "\" viewBox=\"0 0 " + num(width) + " " + num(height) +
          "\" font-family=\"sans-serif\">\n";
  open_.push_back("svg");
}

void SvgDocument::write_start(std::string_view tag, std::initializer_list<Attr> attrs) {
  out_ += '<';
  out_ += tag;
  for (const Attr& a : attrs) {
    out_ += ' ';
    out_ += a.name;
    out_ += "=\"";
    out_ += escape_xml(a.value);
    out_ += '"';
  }
}

void SvgDocument::leaf(std::string_view tag, std::initializer_list<Attr> attrs) {
  write_start(tag, attrs);
  out_ += "/>\n";
}

void SvgDocument::text(std::string_view content, std::initializer_list<Attr> attrs) {
  write_start("text", attrs);
  out_ += '>';
  out_ += escape_xml(content);
  out_ += "</text>\n";
}

void SvgDocument::title(std::string_view content) {
  out_ += "<title>" + escape_xml(content) + "</title>";
}

void SvgDocument::open(std::string_view tag, std::initializer_list<Attr> attrs) {
  write_start(tag, attrs);
  out_ += ">";
  open_.emplace_back(tag);
}

void SvgDocument::close() {
  // The root is closed only by finish(), so a stray close() cannot end the document.
  if (open_.size() <= 1) return;
  out_ += "</" + open_.back() + ">\n";
  open_.pop_back();
}

std::string SvgDocument::finish() {
  while (!open_.empty()) {
    out_ += "</" + open_.back() + ">\n";
    open_.pop_back();
  }
  return std::move(out_);
}

}  // namespace viz
