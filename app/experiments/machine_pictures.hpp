// Pictures of a machine run: the topology with its link traffic and node work
// (SVG), which processor computed each pixel (PNG), when each processor
// traced each tile (SVG, from a run that recorded its tiles), and one HTML
// page with the image, the statistics and those pictures.
// Pure functions of a finished run's report; nothing here runs the machine.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "app/viz/html_report.hpp"
#include "app/viz/machine_drawing.hpp"
#include "app/viz/timeline.hpp"
#include "nodes/machine/machine.hpp"
#include "topology/topology.hpp"
#include "tracer/image.hpp"

namespace app {

// Nodes filled by pixels computed and ringed by page requests served; links by traffic.
viz::MachineDrawing machine_drawing(const nodes::MachineReport& report);
// A drawing of the topology's shape, with no nodes' work or links yet.
viz::MachineDrawing machine_shape(const topology::Topology& topology);

// The node that computed each of width x height pixels (row-major). With SPD
// corner samples ((W+1) x (H+1) items) a pixel belongs to its top-left corner.
std::vector<std::uint16_t> pixel_owners(const nodes::MachineReport& report, int width, int height);

// Every recorded tile on a time axis, wall or virtual as the run was.
viz::Timeline timeline(const nodes::MachineReport& report);

// The statistics of a run as rows for the HTML page.
viz::KeyValueTable machine_statistics(const nodes::MachineReport& report);

// The page's tables: one row per node (work, cache, pages served), one per
// packet kind (packets and hops), and, for a run over several MPI ranks,
// one per rank (its nodes, threads and what crossed the wire).
std::vector<viz::Table> machine_tables(const nodes::MachineReport& report);

struct PictureFiles {
  std::filesystem::path machine_svg;    // empty: not written
  std::filesystem::path ownership_png;  // empty: not written
  std::filesystem::path report_html;    // empty: not written
  std::filesystem::path timeline_svg;   // empty: not written
};

// Every file write_machine_pictures writes for `files`, in order, each with
// the option that asks for it.
std::vector<std::pair<std::string, std::filesystem::path>> picture_outputs(const PictureFiles& files);

// Writes the pictures asked for (none: nothing to do); returns every file written.
// `page` gives the HTML page its title, version and command line; the run's
// section is added to its sections. The
// timeline, alone or in the page, needs a run that recorded its tiles
// (std::invalid_argument otherwise). Throws std::runtime_error naming the path if one
// cannot be written, after removing those it had written. The rendered image is
// taken by value for the page to keep without a copy: a caller done with it moves it in.
std::vector<std::filesystem::path> write_machine_pictures(const PictureFiles& files, viz::Report page,
                                                          tracer::Image image, const nodes::MachineReport& report);

}  // namespace app
