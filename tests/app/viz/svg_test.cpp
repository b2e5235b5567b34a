// Inlinable SVG: no XML declaration, every id and reference prefixed per
// document, and XML escaping.
#include "app/viz/svg.hpp"

#include <gtest/gtest.h>

#include "picture_check.hpp"

namespace viz {
namespace {

const char* const cairo_like =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n"
    "<defs><clipPath id=\"clip1\"><path d=\"M 0 0 L 1 1 Z\"/></clipPath>"
    "<symbol id=\"glyph0-1\"><path d=\"\"/></symbol></defs>\n"
    "<g id=\"surface1\" clip-path=\"url(#clip1)\"><use xlink:href=\"#glyph0-1\" x=\"1\"/></g>\n</svg>\n";

TEST(InlinableSvg, DropsTheDeclaration) {
  const std::string svg = inlinable_svg(cairo_like);
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u) << svg;
  EXPECT_EQ(svg.find("<?xml"), std::string::npos);
}

TEST(InlinableSvg, PrefixesEveryIdAndReference) {
  const std::string a = inlinable_svg(cairo_like), b = inlinable_svg(cairo_like);
  const std::set<std::string> ids_a = test::svg_ids(a), ids_b = test::svg_ids(b);
  ASSERT_EQ(ids_a.size(), 3u);
  for (const std::string& id : ids_a) EXPECT_EQ(ids_b.count(id), 0u) << id;
  EXPECT_EQ(test::svg_references(a).size(), 2u);
  for (const std::string& r : test::svg_references(a)) EXPECT_EQ(ids_a.count(r), 1u) << r;
}

TEST(InlinableSvg, LeavesOtherTextAlone) {
  EXPECT_EQ(inlinable_svg("<svg width=\"3\"><path d=\"M 1 1\"/></svg>"), "<svg width=\"3\"><path d=\"M 1 1\"/></svg>");
}

TEST(EscapeXml, EscapesMarkup) { EXPECT_EQ(escape_xml("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;"); }

}  // namespace
}  // namespace viz
