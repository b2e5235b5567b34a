// HTML report: well-formed, escapes text, links only files it wrote (which
// exist), needs no network, and names every file it may leave behind when
// it fails, so that the caller can remove them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "app/viz/machine.hpp"
#include "app/viz/ownership.hpp"
#include "app/viz/plot.hpp"
#include "app/viz/report.hpp"
#include "tests/support/scratch.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

namespace fs = std::filesystem;

class ReportTest : public ::test::ScratchTest {
 protected:
  ReportTest() : ScratchTest("viz-report-") {}
  static std::string read(const fs::path& p) { return ::test::read_file(p); }
  std::vector<fs::path> write(const fs::path& html, const Report& report) {
    return write_html_report(html, report, [this](const fs::path& p) { tracked_.push_back(p); });
  }
  std::vector<fs::path> tracked_;  // what the writer said it may leave behind
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
  const fs::path html = dir_ / "report.html";
  write(html, sample_report());
  const std::string text = read(html);
  const test::XmlCheck doc = test::check_xml(text);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_NE(text.find("<title>Render &lt;teapot&gt; &amp; &quot;friends&quot;</title>"), std::string::npos);
  EXPECT_NE(text.find("<h1>Render &lt;teapot&gt; &amp; &quot;friends&quot;</h1>"), std::string::npos);
  EXPECT_NE(text.find("&lt;odd&gt; key"), std::string::npos);
  EXPECT_NE(text.find("1 &lt; 2 &amp;&amp; 3 &gt; 2"), std::string::npos);
}

TEST_F(ReportTest, LinksOnlyFilesItWrote) {
  const fs::path html = dir_ / "run 1#a.html";  // a name that needs URL encoding
  const std::vector<fs::path> written = write(html, sample_report());
  ASSERT_EQ(written.size(), 3u);
  EXPECT_EQ(written.back(), html);
  const test::XmlCheck doc = test::check_xml(read(html));
  ASSERT_TRUE(doc.ok) << doc.error;
  std::size_t references = 0;
  for (const auto& e : doc.elements)
    for (const char* attr : {"src", "href", "xlink:href"}) {
      if (!e.attrs.count(attr)) continue;
      ++references;
      const std::string url = e.attrs.at(attr);
      EXPECT_EQ(url.find(':'), std::string::npos) << "not a relative file: " << url;
      EXPECT_EQ(url.find('/'), std::string::npos) << url;
      // Undo the %-encoding of the file name.
      std::string name;
      for (std::size_t i = 0; i < url.size(); ++i) {
        if (url[i] == '%') {
          name += static_cast<char>(std::stoi(url.substr(i + 1, 2), nullptr, 16));
          i += 2;
        } else {
          name += url[i];
        }
      }
      const fs::path target = dir_ / name;
      EXPECT_TRUE(fs::exists(target)) << target;
      EXPECT_NE(std::find(written.begin(), written.end(), target), written.end()) << target;
    }
  EXPECT_EQ(references, 2u);
  const tracer::Rgb8Image png = tracer::read_png(written[0].string());
  EXPECT_EQ(png.width, 4);
  EXPECT_EQ(png.rgb[(1 * 4 + 1) * 3], 255);
}

// A key lists its entries beside the image, in order, each on its colour.
TEST_F(ReportTest, KeyedImageShowsEachEntryOnItsColour) {
  Report r;
  const std::vector<KeyEntry> key{{"0", {255, 255, 0}}, {"1", {0, 0, 128}}, {"<2>", {10, 200, 30}}};
  r.sections.push_back({"owners", {ImageFigure{"owners", tracer::Image(4, 3), key}}});
  const fs::path html = dir_ / "r.html";
  write(html, r);
  const test::XmlCheck doc = test::check_xml(read(html));
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
  const fs::path html = dir_ / "r.html";
  const std::vector<fs::path> written = write(html, sample_report());
  const test::XmlCheck doc = test::check_xml(read(html));
  ASSERT_TRUE(doc.ok) << doc.error;
  std::size_t images = 0;
  for (const auto& e : doc.elements) {
    if (e.tag != "img") continue;
    ++images;
    EXPECT_EQ(e.attrs.at("width"), "256");  // 4 x 3 pixels, 64 times
    EXPECT_EQ(e.attrs.at("height"), "192");
  }
  EXPECT_EQ(images, 2u);
  EXPECT_EQ(tracer::read_png(written[0].string()).width, 4);
  EXPECT_NE(read(html).find("image-rendering: pixelated"), std::string::npos);
}

TEST_F(ReportTest, NeedsNoNetwork) {
  const fs::path html = dir_ / "r.html";
  write(html, sample_report());
  const std::string text = read(html);
  EXPECT_EQ(text.find("<script"), std::string::npos);
  EXPECT_EQ(text.find("<link"), std::string::npos);
  EXPECT_EQ(text.find("@import"), std::string::npos);
  EXPECT_EQ(text.find("url(http"), std::string::npos);
}

TEST_F(ReportTest, RejectsFigureThatIsNotSvg) {
  Report r;
  r.sections.push_back({"bad", {SvgFigure{"x", "<script>alert(1)</script>"}}});
  EXPECT_THROW(write(dir_ / "r.html", r), std::invalid_argument);
}

TEST_F(ReportTest, UnwritableDirectoryIsAnError) {
  EXPECT_THROW(write(dir_ / "missing" / "r.html", sample_report()), std::runtime_error);
}

// The PNGs go out before the page; when the page cannot be put in place
// (here a directory stands at its path) the writer has named each PNG it
// wrote, and not the directory that stood in the way.
TEST_F(ReportTest, APageThatCannotBeWrittenNamesTheImagesItLeft) {
  fs::create_directory(dir_ / "r.html");
  EXPECT_THROW(write(dir_ / "r.html", sample_report()), std::runtime_error);
  std::vector<fs::path> left;
  for (const auto& entry : fs::directory_iterator(dir_))
    if (entry.path().filename() != "r.html") left.push_back(entry.path());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<fs::path>{dir_ / "r-1.png", dir_ / "r-2.png"}));
  EXPECT_EQ(tracked_, left);
}

// Everything written was tracked, the page last.
TEST_F(ReportTest, TracksEveryFileItWrites) {
  const std::vector<fs::path> written = write(dir_ / "r.html", sample_report());
  EXPECT_EQ(tracked_, written);
  EXPECT_EQ(tracked_.back(), dir_ / "r.html");
}

}  // namespace
}  // namespace viz
