// A timeline of a render's farming, drawn with cairo and written as SVG, PNG
// or PDF: one row per processor (node 0 at the top), split into one lane per
// pixel computer (worker 0 at the top, a line between lanes, each lane named
// where it has room), one bar per tile from the time its worker started it
// to the time it finished it, coloured by the page requests it took per
// item, under a time axis. It shows how busy every processor was, how the
// last tiles fall at the end of the run, and which tiles waited on pages.
// Invariants: one row per node and one bar per element of timeline_bars; a
// bar is one tile, except that consecutive tiles of one worker that would
// each be drawn narrower than a pixel, with no visible gap between them,
// share a bar (at most two pixels wide, coloured by their requests over
// their items), so the picture stays small for any number of tiles. Every
// coordinate is finite.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/viz/colour.hpp"
#include "tracer/image.hpp"

namespace viz {

struct TimelineTile {
  int node = 0;
  int worker = 0;  // lane within the node's row
  std::uint32_t first_item = 0;
  std::uint32_t items = 0;
  double start = 0;  // seconds
  double end = 0;
  std::uint64_t page_requests = 0;
};

struct Timeline {
  std::string title{};
  std::string time_axis{"seconds"};  // axis caption, e.g. "wall time (s)"
  int nodes = 1;
  int workers_per_node = 1;
  std::vector<TimelineTile> tiles{};
};

// Each throws std::invalid_argument for nodes or workers outside 1..4096, a
// tile on a node or worker out of range, or a tile whose times are not
// finite, negative, or end before they start.
std::string timeline_svg(const Timeline& t);      // ready to inline, see svg.hpp
std::string timeline_pdf(const Timeline& t);      // the bytes of a PDF file
tracer::Image timeline_image(const Timeline& t);  // at the SVG's size in px

// One bar as the picture draws it, in px from the picture's top left.
struct TimelineBar {
  int node = 0, worker = 0;
  int tiles = 0;  // tiles it stands for
  std::uint64_t items = 0, page_requests = 0;
  double start = 0, end = 0;  // seconds
  double x = 0, y = 0, width = 0, height = 0;
  Rgb8 fill{};
};

// The bars lane by lane (node, then worker), each lane's in order of start.
std::vector<TimelineBar> timeline_bars(const Timeline& t);

}  // namespace viz
