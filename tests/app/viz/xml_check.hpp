// Test helper: a minimal XML well-formedness checker for the SVG and HTML the
// viz library writes. It tracks element nesting, requires quoted attribute
// values and known entities, and collects every attribute so tests can look
// for NaN/inf in coordinates or at referenced files, and the text that opens
// each element (e.g. what a <text> says).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace viz::test {

struct XmlElement {
  std::string tag;
  std::map<std::string, std::string> attrs;
  std::string text;  // character data up to the first child or end tag, entities as written
};

struct XmlCheck {
  bool ok = true;
  std::string error;                  // first problem found
  std::vector<XmlElement> elements;   // in document order
};

// `void_tags` lists HTML elements that never take a closing tag (e.g. "meta").
XmlCheck check_xml(const std::string& text, const std::vector<std::string>& void_tags = {});

std::size_t count_class(const XmlCheck& doc, const std::string& cls);

// The first attribute, as "name=value", whose value holds "nan" or "inf" (a
// coordinate that is not finite); empty if there is none.
std::string first_non_finite_attribute(const XmlCheck& doc);

}  // namespace viz::test
