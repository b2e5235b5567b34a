// Machine drawings: well-formed SVG, one element per node and per link with
// traffic, every kind up to 64 nodes, clear errors for bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <ostream>
#include <stdexcept>

#include "app/viz/machine.hpp"
#include "xml_check.hpp"

namespace viz {
namespace {

// Directed links of each kind, built here from the definitions so the test
// does not depend on the topology library.
std::vector<std::pair<int, int>> neighbours(MachineKind kind, int a, int b) {
  std::vector<std::pair<int, int>> e;
  auto both = [&](int x, int y) { e.push_back({x, y}); e.push_back({y, x}); };
  if (kind == MachineKind::hypercube) {
    for (int i = 0; i < (1 << a); ++i)
      for (int bit = 0; bit < a; ++bit)
        if (!((i >> bit) & 1)) both(i, i | (1 << bit));
  } else if (kind == MachineKind::mesh || kind == MachineKind::torus) {
    const bool wrap = kind == MachineKind::torus;
    for (int y = 0; y < b; ++y)
      for (int x = 0; x < a; ++x) {
        if (x + 1 < a || (wrap && a > 2)) both(y * a + x, y * a + (x + 1) % a);
        if (y + 1 < b || (wrap && b > 2)) both(y * a + x, ((y + 1) % b) * a + x);
      }
  } else if (kind == MachineKind::ring) {
    for (int i = 0; i < a && a > 1; ++i) both(i, (i + 1) % a);
  } else {
    for (int i = 0; i < a; ++i)
      for (int j = i + 1; j < a; ++j) both(i, j);
  }
  return e;
}

// Every third directed link stays idle; the rest carry traffic.
MachineDrawing drawing(MachineKind kind, int a, int b, std::size_t* busy) {
  MachineDrawing m{kind, a, b, "machine <after> render & co", {}, {}};
  const int n = machine_node_count(m);
  for (int i = 0; i < n; ++i) m.nodes.push_back({static_cast<std::uint64_t>(i * 7 % 13), static_cast<std::uint64_t>(i % 5), ""});
  *busy = 0;
  std::uint64_t k = 0;
  for (auto [from, to] : neighbours(kind, a, b)) {
    const std::uint64_t packets = (k++ % 3 == 0) ? 0 : k;
    m.links.push_back({from, to, packets, packets * 1024});
    if (packets > 0) ++*busy;
  }
  return m;
}

struct Case {
  MachineKind kind;
  int a, b;
};

void PrintTo(const Case& c, std::ostream* out) {
  *out << "kind " << static_cast<int>(c.kind) << ", " << c.a << " x " << c.b;
}

class MachineKinds : public ::testing::TestWithParam<Case> {};

TEST_P(MachineKinds, OneElementPerNodeAndPerBusyLink) {
  std::size_t busy = 0;
  const MachineDrawing m = drawing(GetParam().kind, GetParam().a, GetParam().b, &busy);
  const test::XmlCheck doc = test::check_xml(machine_svg(m));
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::count_class(doc, "node"), m.nodes.size());
  EXPECT_EQ(test::count_class(doc, "link"), busy);
  EXPECT_EQ(test::count_class(doc, "idle-link"), m.links.size() - busy);
  for (const auto& e : doc.elements)
    for (const auto& [k, v] : e.attrs) {
      EXPECT_EQ(v.find("nan"), std::string::npos) << k;
      EXPECT_EQ(v.find("inf"), std::string::npos) << k;
    }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, MachineKinds,
                         ::testing::Values(Case{MachineKind::hypercube, 0, 1}, Case{MachineKind::hypercube, 3, 1},
                                           Case{MachineKind::hypercube, 6, 1}, Case{MachineKind::mesh, 8, 8},
                                           Case{MachineKind::mesh, 1, 1}, Case{MachineKind::torus, 4, 4},
                                           Case{MachineKind::torus, 8, 8}, Case{MachineKind::torus, 2, 3},
                                           Case{MachineKind::ring, 64, 1}, Case{MachineKind::ring, 2, 1},
                                           Case{MachineKind::complete, 16, 1}, Case{MachineKind::complete, 1, 1}));

// The font size of each node's label, in node order.
std::vector<double> label_sizes(const test::XmlCheck& doc) {
  std::vector<double> sizes;
  bool in_node = false;
  for (const auto& e : doc.elements) {
    if (e.attrs.count("class") && e.attrs.at("class") == "node") in_node = true;
    if (in_node && e.tag == "text") {
      sizes.push_back(std::stod(e.attrs.at("font-size")));
      in_node = false;
    }
  }
  return sizes;
}

class SixtyFourNodes : public ::testing::TestWithParam<Case> {};

TEST_P(SixtyFourNodes, LabelsAreLegible) {
  std::size_t busy = 0;
  const test::XmlCheck doc = test::check_xml(machine_svg(drawing(GetParam().kind, GetParam().a, GetParam().b, &busy)));
  ASSERT_TRUE(doc.ok) << doc.error;
  const std::vector<double> sizes = label_sizes(doc);
  ASSERT_EQ(sizes.size(), 64u);
  for (double size : sizes) EXPECT_GE(size, 10.0);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, SixtyFourNodes,
                         ::testing::Values(Case{MachineKind::ring, 64, 1}, Case{MachineKind::complete, 64, 1},
                                           Case{MachineKind::hypercube, 6, 1}, Case{MachineKind::mesh, 8, 8},
                                           Case{MachineKind::torus, 8, 8}));

// A complete graph of 256 nodes has 65280 directed links: drawn in bulk,
// every busy link is a stroke of one of a few traffic bands, the idle ones
// are only counted, and the file stays small.
TEST(MachineDrawing, ManyLinksAreDrawnInBulk) {
  std::size_t busy = 0;
  const MachineDrawing m = drawing(MachineKind::complete, 256, 1, &busy);
  const std::string svg = machine_svg(m);
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::count_class(doc, "link"), 0u);
  EXPECT_EQ(test::count_class(doc, "idle-link"), 0u);
  const std::size_t bands = test::count_class(doc, "link-band");
  EXPECT_GE(bands, 1u);
  EXPECT_LE(bands, 16u);
  std::size_t strokes = 0;
  for (const auto& e : doc.elements)
    if (e.attrs.count("class") && e.attrs.at("class") == "link-band")
      strokes += static_cast<std::size_t>(std::count(e.attrs.at("d").begin(), e.attrs.at("d").end(), 'M'));
  EXPECT_EQ(strokes, busy);
  EXPECT_NE(svg.find(std::to_string(m.links.size() - busy) + " idle links not drawn"), std::string::npos);
  EXPECT_LT(svg.size(), 2'000'000u);
}

// Everything the legend's text says, in order.
std::string legend_text(const test::XmlCheck& doc) {
  std::string text;
  bool in_legend = false;
  for (const auto& e : doc.elements) {
    if (e.attrs.count("class") && e.attrs.at("class") == "legend") in_legend = true;
    if (in_legend && e.tag == "text") text += e.text + "\n";
  }
  return text;
}

TEST(MachineDrawing, LegendExplainsIdleAndWrapLinks) {
  std::size_t busy = 0;
  const std::string torus = legend_text(test::check_xml(machine_svg(drawing(MachineKind::torus, 4, 4, &busy))));
  EXPECT_NE(torus.find("idle link"), std::string::npos) << torus;
  EXPECT_NE(torus.find("wrap-around links"), std::string::npos) << torus;
  const std::string mesh = legend_text(test::check_xml(machine_svg(drawing(MachineKind::mesh, 4, 4, &busy))));
  EXPECT_NE(mesh.find("idle link"), std::string::npos) << mesh;
  EXPECT_EQ(mesh.find("wrap"), std::string::npos) << mesh;
}

// One node: no links and no pages served, so neither is in the legend.
TEST(MachineDrawing, LegendOfASingleNodeHasNoLinksOrRings) {
  const MachineDrawing m{MachineKind::complete, 1, 1, "", {{4096, 0, ""}}, {}};
  const test::XmlCheck doc = test::check_xml(machine_svg(m));
  ASSERT_TRUE(doc.ok) << doc.error;
  const std::string legend = legend_text(doc);
  EXPECT_NE(legend.find("node fill: pixels computed"), std::string::npos) << legend;
  EXPECT_EQ(legend.find("link"), std::string::npos) << legend;
  EXPECT_EQ(legend.find("ring width"), std::string::npos) << legend;
}

TEST(MachineDrawing, EscapesTitleAndLabels) {
  std::size_t busy = 0;
  MachineDrawing m = drawing(MachineKind::ring, 4, 1, &busy);
  m.nodes[2].label = "a<b>&c";
  const std::string svg = machine_svg(m);
  EXPECT_NE(svg.find("machine &lt;after&gt; render &amp; co"), std::string::npos);
  EXPECT_NE(svg.find(">a&lt;b&gt;&amp;c<"), std::string::npos);
  EXPECT_TRUE(test::check_xml(svg).ok);
}

TEST(MachineDrawing, BusiestLinkIsWidest) {
  MachineDrawing m{MachineKind::ring, 3, 1, "", {{}, {}, {}}, {{0, 1, 10, 100}, {1, 2, 10, 5000}, {2, 0, 10, 1000}}};
  const test::XmlCheck doc = test::check_xml(machine_svg(m));
  std::vector<double> widths;
  for (const auto& e : doc.elements)
    if (e.attrs.count("class") && e.attrs.at("class") == "link") widths.push_back(std::stod(e.attrs.at("stroke-width")));
  // Drawn lightest first, so widths rise along the document.
  ASSERT_EQ(widths.size(), 3u);
  EXPECT_LT(widths[0], widths[1]);
  EXPECT_LT(widths[1], widths[2]);
}

TEST(MachineDrawing, RejectsNodeCountMismatch) {
  MachineDrawing m{MachineKind::mesh, 4, 4, "", std::vector<NodeWork>(15), {}};
  EXPECT_THROW(machine_svg(m), std::invalid_argument);
}

TEST(MachineDrawing, RejectsLinkOutOfRange) {
  MachineDrawing m{MachineKind::ring, 4, 1, "", std::vector<NodeWork>(4), {{0, 4, 1, 1}}};
  EXPECT_THROW(machine_svg(m), std::invalid_argument);
}

TEST(MachineDrawing, RejectsImpossibleDimensions) {
  EXPECT_THROW(machine_node_count({MachineKind::hypercube, 13, 1, "", {}, {}}), std::invalid_argument);
  EXPECT_THROW(machine_node_count({MachineKind::mesh, 0, 4, "", {}, {}}), std::invalid_argument);
  EXPECT_THROW(machine_node_count({MachineKind::ring, 5000, 1, "", {}, {}}), std::invalid_argument);
  EXPECT_EQ(machine_node_count({MachineKind::torus, 8, 4, "", {}, {}}), 32);
}

}  // namespace
}  // namespace viz
