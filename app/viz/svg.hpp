// Minimal SVG text building for the viz library: XML escaping, finite number
// formatting and an element writer that always produces well-formed output.
// Invariants: every attribute value is quoted and escaped; every opened
// element is closed (finish() closes what is left); no number written is NaN
// or infinite. The result has no XML declaration, so it can be inlined in HTML.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace viz {

// Escapes & < > " ' for element text and attribute values alike.
std::string escape_xml(std::string_view text);

// Shortest readable form with at most 2 decimals; a non-finite value is
// written as 0 so that no NaN ever reaches a coordinate.
std::string num(double value);

struct Attr {
  std::string_view name;
  std::string value;  // raw text; escaped when written
};

class SvgDocument {
 public:
  SvgDocument(double width, double height);

  void leaf(std::string_view tag, std::initializer_list<Attr> attrs);
  void text(std::string_view content, std::initializer_list<Attr> attrs);
  // A <title> child: browsers show it as a tooltip of the enclosing element.
  void title(std::string_view content);
  void open(std::string_view tag, std::initializer_list<Attr> attrs);
  void close();
  // Closes every element still open, including the root, and returns the text.
  std::string finish();

 private:
  void write_start(std::string_view tag, std::initializer_list<Attr> attrs);

  std::string out_;
  std::vector<std::string> open_;  // tags awaiting their closing tag
};

}  // namespace viz
