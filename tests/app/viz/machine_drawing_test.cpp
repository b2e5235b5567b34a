// Machine drawings: well-formed SVG and valid PDF for every kind, every node
// drawn in its work colour, legible labels up to 64 nodes, legends that say
// only what the picture has, clear errors for bad input.
#include "app/viz/machine_drawing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <ostream>
#include <stdexcept>

#include "app/viz/colour.hpp"
#include "picture_check.hpp"
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

TEST_P(MachineKinds, SvgIsWellFormedAndPdfIsAPdf) {
  std::size_t busy = 0;
  const MachineDrawing m = drawing(GetParam().kind, GetParam().a, GetParam().b, &busy);
  const std::string svg = machine_svg(m);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  EXPECT_EQ(test::first_non_finite_attribute(doc), "");
  EXPECT_TRUE(test::is_pdf(machine_pdf(m)));
}

// Every node is a disk of its work colour (sampled below its label), inside the picture.
TEST_P(MachineKinds, EveryNodeIsFilledByItsWork) {
  std::size_t busy = 0;
  const MachineDrawing m = drawing(GetParam().kind, GetParam().a, GetParam().b, &busy);
  const tracer::Rgb8Image img = machine_image(m).to_rgb8();
  const std::vector<NodePlace> places = machine_node_places(m);
  ASSERT_EQ(places.size(), m.nodes.size());
  std::uint64_t most = 0;
  for (const NodeWork& w : m.nodes) most = std::max(most, w.pixels);
  for (std::size_t i = 0; i < places.size(); ++i) {
    const NodePlace& p = places[i];
    ASSERT_GT(p.radius, 4);
    const int x = static_cast<int>(p.x), y = static_cast<int>(p.y + 0.65 * p.radius);
    ASSERT_TRUE(x >= 0 && x < img.width && y >= 0 && y < img.height) << i;
    const double f = most ? static_cast<double>(m.nodes[i].pixels) / static_cast<double>(most) : 0.0;
    EXPECT_TRUE(test::near(test::pixel(img, x, y), work_scale(f), 2)) << "node " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, MachineKinds,
                         ::testing::Values(Case{MachineKind::hypercube, 0, 1}, Case{MachineKind::hypercube, 3, 1},
                                           Case{MachineKind::hypercube, 6, 1}, Case{MachineKind::mesh, 8, 8},
                                           Case{MachineKind::mesh, 1, 1}, Case{MachineKind::torus, 4, 4},
                                           Case{MachineKind::torus, 8, 8}, Case{MachineKind::torus, 2, 3},
                                           Case{MachineKind::ring, 64, 1}, Case{MachineKind::ring, 2, 1},
                                           Case{MachineKind::complete, 16, 1}, Case{MachineKind::complete, 1, 1}));

class SixtyFourNodes : public ::testing::TestWithParam<Case> {};

TEST_P(SixtyFourNodes, LabelsAreLegible) {
  std::size_t busy = 0;
  const std::vector<NodePlace> places =
      machine_node_places(drawing(GetParam().kind, GetParam().a, GetParam().b, &busy));
  ASSERT_EQ(places.size(), 64u);
  for (const NodePlace& p : places) EXPECT_GE(p.label_size, 10.0);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, SixtyFourNodes,
                         ::testing::Values(Case{MachineKind::ring, 64, 1}, Case{MachineKind::complete, 64, 1},
                                           Case{MachineKind::hypercube, 6, 1}, Case{MachineKind::mesh, 8, 8},
                                           Case{MachineKind::torus, 8, 8}));

// A complete graph of 256 nodes has 65280 directed links: drawn in bulk, the
// idle ones only counted in the legend, and the file stays small.
TEST(MachineDrawing, ManyLinksAreDrawnInBulk) {
  std::size_t busy = 0;
  const MachineDrawing m = drawing(MachineKind::complete, 256, 1, &busy);
  const std::string svg = machine_svg(m);
  const test::XmlCheck doc = test::check_xml(svg);
  ASSERT_TRUE(doc.ok) << doc.error;
  std::size_t paths = 0;
  for (const auto& e : doc.elements) paths += e.tag == "path";
  EXPECT_LT(paths, 16 + 256 * 8u);  // bands, nodes and their labels: not a path per link
  EXPECT_LT(svg.size(), 4'000'000u);
  const std::vector<std::string> notes = machine_legend_notes(m);
  EXPECT_NE(std::find(notes.begin(), notes.end(), std::to_string(m.links.size() - busy) + " idle links not drawn"),
            notes.end());
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  return text;
}

TEST(MachineDrawing, LegendExplainsIdleAndWrapLinks) {
  std::size_t busy = 0;
  const std::string torus = joined(machine_legend_notes(drawing(MachineKind::torus, 4, 4, &busy)));
  EXPECT_NE(torus.find("idle link"), std::string::npos) << torus;
  EXPECT_NE(torus.find("wrap-around links"), std::string::npos) << torus;
  const std::string mesh = joined(machine_legend_notes(drawing(MachineKind::mesh, 4, 4, &busy)));
  EXPECT_NE(mesh.find("idle link"), std::string::npos) << mesh;
  EXPECT_EQ(mesh.find("wrap"), std::string::npos) << mesh;
}

// One node: no links and no pages served, so neither is in the legend.
TEST(MachineDrawing, LegendOfASingleNodeHasNoLinksOrRings) {
  const MachineDrawing m{MachineKind::complete, 1, 1, "", {{4096, 0, ""}}, {}};
  EXPECT_TRUE(machine_legend_notes(m).empty()) << joined(machine_legend_notes(m));
  EXPECT_TRUE(test::check_xml(machine_svg(m)).ok);
}

// The title is drawn: dark text pixels at the top of the picture, none without it.
TEST(MachineDrawing, TitleIsDrawn) {
  std::size_t busy = 0;
  MachineDrawing m = drawing(MachineKind::ring, 4, 1, &busy);
  const tracer::Rgb8Image titled = machine_image(m).to_rgb8();
  EXPECT_GT(test::dark_pixels(titled, 0, 0, titled.width, 28), 50);
  EXPECT_GT(test::intermediate_greys(titled, 0, 0, titled.width, 28), 20);
  m.title.clear();
  const tracer::Rgb8Image untitled = machine_image(m).to_rgb8();
  EXPECT_EQ(test::dark_pixels(untitled, 0, 0, untitled.width, 8), 0);
}

TEST(MachineDrawing, RejectsNodeCountMismatch) {
  MachineDrawing m{MachineKind::mesh, 4, 4, "", std::vector<NodeWork>(15), {}};
  EXPECT_THROW(machine_svg(m), std::invalid_argument);
  EXPECT_THROW(machine_image(m), std::invalid_argument);
  EXPECT_THROW(machine_pdf(m), std::invalid_argument);
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
