// HTML report: well-formed, escapes text, stands alone (its images embedded
// as PNG data: URLs that decode to the images, nothing referenced outside
// the page), says what made it, and refuses a figure that is not SVG.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "app/viz/html_report.hpp"
#include "app/viz/machine_drawing.hpp"
#include "app/viz/ownership.hpp"
#include "app/viz/plot.hpp"
#include "tests/support/scratch.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

namespace fs = std::filesystem;

class ReportTest : public ::test::ScratchTest {
 protected:
  ReportTest() : ScratchTest("viz-report-") {}
  // The PNG a data: URL holds, decoded through a file (the reader reads files).
  tracer::Rgb8Image decode_png(const std::string& url) {
    const std::string prefix = "data:image/png;base64,";
    EXPECT_EQ(url.rfind(prefix, 0), 0u) << url.substr(0, 40);
    static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string bytes;
    std::uint32_t bits = 0;
    int held = 0;
    for (char c : url.substr(prefix.size())) {
      if (c == '=') break;
      const std::size_t v = digits.find(c);
      EXPECT_NE(v, std::string::npos) << "not base64: " << c;
      bits = (bits << 6) | std::uint32_t(v);
      held += 6;
      if (held >= 8) {
        held -= 8;
        bytes += static_cast<char>((bits >> held) & 0xff);
      }
    }
    const fs::path png = dir_ / ("decoded-" + std::to_string(decoded_++) + ".png");
    std::ofstream(png, std::ios::binary) << bytes;
    return tracer::read_png(png.string());
  }
  int decoded_ = 0;
};

Report sample_report() {
  tracer::Image render(4, 3);
  render.at(1, 1) = {1, 0.5f, 0};
  LinePlot plot;
  plot.title = "efficiency";
  plot.series.push_back({"teapot", {{1, 0.9}, {2, 0.8}}});
  MachineDrawing m{MachineKind::ring, 3, 1, "ring", std::vector<NodeWork>(3), {{0, 1, 2, 64}}};
  Report r;
  r.title = "Render <teapot> & \"friends\"";
  r.sections.push_back({"Image", {ImageFigure{"rendered", render},
                                  ImageFigure{"owners", ownership_image(4, 3, std::vector<std::uint16_t>(12, 1))}}});
  r.sections.push_back({"Statistics", {KeyValueTable{"rays", {{"primary", "262144"}, {"<odd> key", "a&b"}}},
                                       Table{"per node", {"node", "pixels"}, {{"0", "100"}, {"1", "97"}}},
                                       Paragraph{"1 < 2 && 3 > 2"}}});
  r.sections.push_back({"Pictures", {SvgFigure{"plot", plot_svg(plot)}, SvgFigure{"machine", machine_svg(m)}}});
  return r;
}

TEST_F(ReportTest, IsWellFormedAndEscapesText) {
  const std::string text = html_report(sample_report());
  const test::XmlCheck doc = test::check_xml(text);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_NE(text.find("<title>Render &lt;teapot&gt; &amp; &quot;friends&quot;</title>"), std::string::npos);
  EXPECT_NE(text.find("<h1>Render &lt;teapot&gt; &amp; &quot;friends&quot;</h1>"), std::string::npos);
  EXPECT_NE(text.find("&lt;odd&gt; key"), std::string::npos);
  EXPECT_NE(text.find("1 &lt; 2 &amp;&amp; 3 &gt; 2"), std::string::npos);
}

// Every reference is an embedded image or a place in the page itself.
TEST_F(ReportTest, EmbedsItsImagesAndReferencesNothingOutside) {
  const test::XmlCheck doc = test::check_xml(html_report(sample_report()));
  ASSERT_TRUE(doc.ok) << doc.error;
  std::vector<tracer::Rgb8Image> images;
  for (const auto& e : doc.elements)
    for (const char* attr : {"src", "href", "xlink:href"}) {
      if (!e.attrs.count(attr)) continue;
      const std::string url = e.attrs.at(attr);
      if (url.starts_with("#")) continue;
      images.push_back(decode_png(url));
    }
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].width, 4);
  EXPECT_EQ(images[0].height, 3);
  tracer::Image render(4, 3);
  render.at(1, 1) = {1, 0.5f, 0};
  EXPECT_EQ(images[0].rgb, render.to_rgb8().rgb);
  EXPECT_EQ(images[1].rgb, ownership_image(4, 3, std::vector<std::uint16_t>(12, 1)).to_rgb8().rgb);
}

// The page names the program and the command that made it, quoted as a shell needs it.
TEST_F(ReportTest, SaysWhatMadeIt) {
  Report r = sample_report();
  r.version = "vmpray 9.9";
  r.command_line = {"vmpray", "teapot", "--report", "my run.html", "it's"};
  const std::string text = html_report(r);
  ASSERT_TRUE(test::check_xml(text).ok);
  EXPECT_NE(text.find("Made by vmpray 9.9 with <code>vmpray teapot --report &#39;my run.html&#39; "
                      "&#39;it&#39;\\&#39;&#39;s&#39;</code>"),
            std::string::npos)
      << text.substr(0, 2000);
  EXPECT_EQ(html_report(sample_report()).find("Made by"), std::string::npos);  // not known: not said
}

TEST(ShellQuoted, QuotesOnlyWhatAShellWouldSplitOrExpand) {
  EXPECT_EQ(shell_quoted({"vmpray", "teapot", "--topology", "mesh:4x4", "-o", "a/b.png"}),
            "vmpray teapot --topology mesh:4x4 -o a/b.png");
  EXPECT_EQ(shell_quoted({"a b", "", "$x", "*"}), "'a b' '' '$x' '*'");
  EXPECT_EQ(shell_quoted({"it's"}), "'it'\\''s'");
}

// A key lists its entries beside the image, in order, each on its colour.
TEST_F(ReportTest, KeyedImageShowsEachEntryOnItsColour) {
  Report r;
  const std::vector<KeyEntry> key{{"0", {255, 255, 0}}, {"1", {0, 0, 128}}, {"<2>", {10, 200, 30}}};
  r.sections.push_back({"owners", {ImageFigure{"owners", tracer::Image(4, 3), key}}});
  const test::XmlCheck doc = test::check_xml(html_report(r));
  ASSERT_TRUE(doc.ok) << doc.error;
  ASSERT_EQ(test::count_class(doc, "key"), 1u);
  std::vector<test::XmlElement> items;
  for (const auto& e : doc.elements)
    if (e.tag == "li") items.push_back(e);
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(items[0].text, "0");
  EXPECT_EQ(items[2].text, "&lt;2&gt;");
  EXPECT_NE(items[0].attrs.at("style").find("background:#ffff00"), std::string::npos);
  EXPECT_NE(items[0].attrs.at("style").find("color:#000000"), std::string::npos);  // dark on light
  EXPECT_NE(items[1].attrs.at("style").find("background:#000080"), std::string::npos);
  EXPECT_NE(items[1].attrs.at("style").find("color:#ffffff"), std::string::npos);  // light on dark
}

// Small images are shown enlarged by a whole factor, to at least 256 px;
// the PNG keeps the image's size.
TEST_F(ReportTest, SmallImagesAreShownEnlarged) {
  const std::string text = html_report(sample_report());
  const test::XmlCheck doc = test::check_xml(text);
  ASSERT_TRUE(doc.ok) << doc.error;
  std::size_t images = 0;
  for (const auto& e : doc.elements) {
    if (e.tag != "img") continue;
    ++images;
    EXPECT_EQ(e.attrs.at("width"), "256");  // 4 x 3 pixels, 64 times
    EXPECT_EQ(e.attrs.at("height"), "192");
    EXPECT_EQ(decode_png(e.attrs.at("src")).width, 4);
  }
  EXPECT_EQ(images, 2u);
  EXPECT_NE(text.find("image-rendering: pixelated"), std::string::npos);
}

TEST_F(ReportTest, NeedsNoNetwork) {
  const std::string text = html_report(sample_report());
  EXPECT_EQ(text.find("<script"), std::string::npos);
  EXPECT_EQ(text.find("<link"), std::string::npos);
  EXPECT_EQ(text.find("@import"), std::string::npos);
  EXPECT_EQ(text.find("url(http"), std::string::npos);
}

TEST_F(ReportTest, RejectsFigureThatIsNotSvg) {
  Report r;
  r.sections.push_back({"bad", {SvgFigure{"x", "<script>alert(1)</script>"}}});
  EXPECT_THROW(html_report(r), std::invalid_argument);
}

}  // namespace
}  // namespace viz
