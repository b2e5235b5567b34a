// A picture of the machine after a render, drawn with cairo and written as
// SVG, PNG or PDF: every processor a disk filled by the pixels it computed
// and ringed by the page requests it served, every directed link coloured
// and sized by its traffic. Layouts: a hypercube's even bits along x and
// odd bits along y, gaps growing per level; mesh and torus on their grid
// (id = y * W + x, wrap links as arcs leaving the border); ring and complete
// graph on a circle, node 0 at the top, ids clockwise. The picture grows
// with the layout, up to a bound, so labels stay legible (10 px at least up
// to 64 nodes). Invariants: one disk per node; up to 4096 listed links, one
// stroke per directed link that carried packets (the two directions side by
// side, heaviest on top) and a thin grey one per idle link; more links are
// drawn in bulk, busy ones grouped by traffic into at most 16 strokes, idle
// ones left out and counted in the legend.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tracer/image.hpp"

namespace viz {

enum class MachineKind { hypercube, mesh, torus, ring, complete };

struct NodeWork {
  std::uint64_t pixels = 0;                // pixels computed by this node
  std::uint64_t page_requests_served = 0;  // by its page server
  std::string label{};                     // drawn in the node; empty: its id
};

struct LinkTraffic {
  int from = 0;  // the link carries packets from `from` to `to` (neighbours)
  int to = 0;
  std::uint64_t packets = 0;
  std::uint64_t bytes = 0;
};

struct MachineDrawing {
  MachineKind kind = MachineKind::ring;
  int dim_a = 1;  // hypercube: dimension d; mesh/torus: width W; ring/complete: N
  int dim_b = 1;  // mesh/torus: height H; unused otherwise
  std::string title{};
  std::vector<NodeWork> nodes{};     // index = node id
  std::vector<LinkTraffic> links{};  // directed; colour and width by bytes (packets if no bytes given)
};

// Number of nodes the kind and dimensions describe; throws
// std::invalid_argument naming the problem for impossible dimensions.
int machine_node_count(const MachineDrawing& m);

// Each throws std::invalid_argument if nodes.size() does not match the
// topology or a link names a node out of range.
std::string machine_svg(const MachineDrawing& m);      // ready to inline, see svg.hpp
std::string machine_pdf(const MachineDrawing& m);      // the bytes of a PDF file
tracer::Image machine_image(const MachineDrawing& m);  // at the SVG's size in px

// Where the picture draws node i, in px: its centre, radius and the font
// size of its label.
struct NodePlace {
  double x = 0, y = 0, radius = 0, label_size = 0;
};
std::vector<NodePlace> machine_node_places(const MachineDrawing& m);

// The lines of the legend under the colour bars, in order: only what the
// picture has (rings if some node served pages, the rest if there are links).
std::vector<std::string> machine_legend_notes(const MachineDrawing& m);

}  // namespace viz
