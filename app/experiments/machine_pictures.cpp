// Machine drawing, pixel ownership, the tile timeline and the run's HTML page
// (see machine_pictures.hpp).
#include "app/experiments/machine_pictures.hpp"

#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "app/experiments/points.hpp"
#include "app/render/machine_summary.hpp"
#include "app/render/output_files.hpp"
#include "app/viz/ownership.hpp"
#include "nodes/machine/messages.hpp"
#include "topology/topology.hpp"

namespace app {

namespace {

// Which colour the ownership picture gives each processor.
std::vector<viz::KeyEntry> ownership_key(int nodes) {
  std::vector<viz::KeyEntry> key;
  for (int n = 0; n < nodes; ++n) key.push_back({std::to_string(n), viz::node_colour(n)});
  return key;
}

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
}

}  // namespace

viz::MachineDrawing machine_shape(const topology::Topology& topo) {
  viz::MachineDrawing m;
  switch (topo.kind()) {
    case topology::Kind::hypercube: m.kind = viz::MachineKind::hypercube; break;
    case topology::Kind::mesh: m.kind = viz::MachineKind::mesh; break;
    case topology::Kind::torus: m.kind = viz::MachineKind::torus; break;
    case topology::Kind::ring: m.kind = viz::MachineKind::ring; break;
    case topology::Kind::complete: m.kind = viz::MachineKind::complete; break;
  }
  const bool grid = topo.kind() == topology::Kind::mesh || topo.kind() == topology::Kind::torus;
  m.dim_a = static_cast<int>(topo.kind() == topology::Kind::hypercube ? topo.dimension() : topo.width());
  m.dim_b = grid ? static_cast<int>(topo.height()) : 1;
  return m;
}

viz::MachineDrawing machine_drawing(const nodes::MachineReport& report) {
  viz::MachineDrawing m = machine_shape(report.topology);
  m.title = report.topology.spec() + ": pixels computed (fill), pages served (ring), link traffic";
  for (const nodes::NodeReport& n : report.per_node)
    m.nodes.push_back(viz::NodeWork{.pixels = n.work.items, .page_requests_served = n.served.pages_served});
  for (const nodes::LinkStats& l : report.network.links)
    m.links.push_back(viz::LinkTraffic{static_cast<int>(l.from), static_cast<int>(l.to), l.packets, l.bytes});
  return m;
}

std::vector<std::uint16_t> pixel_owners(const nodes::MachineReport& report, int width, int height) {
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (report.owners.size() == pixels) return report.owners;
  const auto corners = static_cast<std::size_t>(width + 1) * static_cast<std::size_t>(height + 1);
  if (report.owners.size() != corners)
    throw std::invalid_argument("pixel owners: the run recorded " + std::to_string(report.owners.size()) +
                                " items for a " + std::to_string(width) + "x" + std::to_string(height) + " image");
  std::vector<std::uint16_t> owners(pixels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      owners[static_cast<std::size_t>(y) * width + x] = report.owners[static_cast<std::size_t>(y) * (width + 1) + x];
  return owners;
}

viz::Timeline timeline(const nodes::MachineReport& report) {
  viz::Timeline t;
  t.title = report.topology.spec() + ", " + std::to_string(report.threads) +
            (report.threads == 1 ? " thread" : " threads") +
            (report.ranks.empty() ? "" : " per rank, " + std::to_string(report.ranks.size()) + " ranks") +
            ": tiles over time";
  t.time_axis = !report.model ? "wall time (s)" : "virtual time (s)";
  t.nodes = report.nodes;
  t.workers_per_node = report.workers_per_node;
  for (std::size_t n = 0; n < report.per_node.size(); ++n)
    for (const nodes::TileSpan& s : report.per_node[n].work.spans)
      t.tiles.push_back({static_cast<int>(n), s.worker, s.tile.first, s.tile.count, s.start, s.end, s.page_requests});
  return t;
}

viz::KeyValueTable machine_statistics(const nodes::MachineReport& r) {
  const tracer::RayStats rays = r.rays();
  const nodes::SvmStats svm = r.svm();
  viz::KeyValueTable t{.caption = "Run"};
  t.rows = {{"topology", r.topology.spec()},
            {"processors", std::to_string(r.nodes)},
            {"cache per node (pages)", std::to_string(r.cache_pages)},
            {"database pages", std::to_string(r.page_count) + " of " + std::to_string(r.page_size) + " bytes"},
            {"rays", std::to_string(rays.rays())},
            {"page accesses", std::to_string(svm.accesses())},
            {"page requests (misses)", std::to_string(svm.misses)},
            {"miss ratio", fixed(100 * svm.miss_ratio(), 3) + "%"},
            {"pages served", std::to_string(r.served().pages_served)},
            {"mean hops per message", fixed(r.network.hops.mean(), 2)},
            {"links cut between ranks", std::to_string(r.cut_links)},
            {"pixel imbalance (max/mean)", fixed(r.item_imbalance(), 3)},
            {"wall time", fixed(r.wall_seconds, 2) + " s"}};
  if (!!r.model) {
    t.rows.push_back({"machine model", r.model->describe()});
    t.rows.push_back({"predicted synthesis time", paper_duration(r.predicted_seconds)});
  }
  return t;
}

std::vector<viz::Table> machine_tables(const nodes::MachineReport& r) {
  std::vector<viz::Table> tables;
  viz::Table per_node{.caption = "Per node",
                      .header = {"node", "pixels", "tiles", "rays", "page accesses", "misses", "miss ratio",
                                 "pages served", "cache pages", "evictions"}};
  for (std::size_t n = 0; n < r.per_node.size(); ++n) {
    const nodes::NodeReport& x = r.per_node[n];
    per_node.rows.push_back({std::to_string(n), std::to_string(x.work.items), std::to_string(x.work.tiles),
                             std::to_string(x.work.rays.rays()), std::to_string(x.svm.accesses()),
                             std::to_string(x.svm.misses), fixed(100 * x.svm.miss_ratio(), 3) + "%",
                             std::to_string(x.served.pages_served), std::to_string(x.cache_capacity),
                             std::to_string(x.evictions)});
  }
  tables.push_back(std::move(per_node));
  viz::Table hops{.caption = "Hops by packet kind", .header = {"kind", "packets", "mean hops", "most hops"}};
  for (const auto& [kind, h] : r.network.hops_by_kind)
    hops.rows.push_back({std::string(nodes::message_kind_name(kind)), std::to_string(h.packets), fixed(h.mean(), 2),
                         std::to_string(h.max_hops)});
  hops.rows.push_back({"all", std::to_string(r.network.hops.packets), fixed(r.network.hops.mean(), 2),
                       std::to_string(r.network.hops.max_hops)});
  tables.push_back(std::move(hops));
  if (!r.ranks.empty()) {
    viz::Table ranks{.caption = "Per MPI rank (" + std::to_string(r.cut_links) + " links cut)",
                     .header = {"rank", "nodes", "threads", "packets sent", "bytes sent", "packets received",
                                "bytes received", "MPI messages", "scene bytes at peak", "cpu (s)", "wall (s)"}};
    for (const nodes::RankReport& k : r.ranks)
      ranks.rows.push_back({std::to_string(k.rank), rank_nodes(k), std::to_string(k.threads),
                            std::to_string(k.bridge.packets_sent), std::to_string(k.bridge.bytes_sent),
                            std::to_string(k.bridge.packets_received), std::to_string(k.bridge.bytes_received),
                            std::to_string(k.bridge.messages_sent), std::to_string(k.peak_scene_bytes),
                            fixed(k.cpu_seconds, 3), fixed(k.wall_seconds, 3)});
    tables.push_back(std::move(ranks));
  }
  return tables;
}

std::vector<std::pair<std::string, std::filesystem::path>> picture_outputs(const PictureFiles& files) {
  std::vector<std::pair<std::string, std::filesystem::path>> out;
  if (!files.machine_svg.empty()) out.emplace_back("--machine-svg", files.machine_svg);
  if (!files.ownership_png.empty()) out.emplace_back("--ownership", files.ownership_png);
  if (!files.timeline_svg.empty()) out.emplace_back("--timeline", files.timeline_svg);
  if (!files.report_html.empty()) out.emplace_back("--report", files.report_html);
  return out;
}

std::vector<std::filesystem::path> write_machine_pictures(const PictureFiles& files, viz::Report page,
                                                          tracer::Image image, const nodes::MachineReport& report) {
  std::vector<std::filesystem::path> written;
  if (files.machine_svg.empty() && files.ownership_png.empty() && files.report_html.empty() &&
      files.timeline_svg.empty())
    return written;
  const std::string machine = viz::machine_svg(machine_drawing(report));
  std::string tiles;
  if (!files.timeline_svg.empty() || !files.report_html.empty()) {
    const viz::Timeline t = timeline(report);
    if (t.tiles.size() != report.farmer.tiles)
      throw std::invalid_argument("tile timeline: the run recorded " + std::to_string(t.tiles.size()) + " of its " +
                                  std::to_string(report.farmer.tiles) + " tiles");
    tiles = viz::timeline_svg(t);
  }
  tracer::Image ownership =
      viz::ownership_image(image.width(), image.height(), pixel_owners(report, image.width(), image.height()));
  OutputFiles outputs;
  if (!files.machine_svg.empty()) written.push_back(outputs.write_text(files.machine_svg, machine));
  if (!files.ownership_png.empty())
    written.push_back(outputs.write(files.ownership_png, [&](const auto& p) {
      viz::ownership_picture(ownership, ownership_key(static_cast<int>(report.nodes))).write_image(p.string());
    }));
  if (!files.timeline_svg.empty()) written.push_back(outputs.write_text(files.timeline_svg, tiles));
  if (!files.report_html.empty()) {
    // The page takes the image and the ownership picture themselves: a copy
    // of either would be one more image-sized buffer at the outputs' peak.
    viz::Section run{.heading = "The run on " + report.topology.spec()};
    run.blocks.push_back(viz::ImageFigure{.caption = "rendered image", .image = std::move(image)});
    run.blocks.push_back(machine_statistics(report));
    for (viz::Table& t : machine_tables(report)) run.blocks.push_back(std::move(t));
    run.blocks.push_back(viz::SvgFigure{.caption = "the machine after the run", .svg = machine});
    run.blocks.push_back(viz::ImageFigure{.caption = "which processor computed each pixel (key: processor numbers)",
                                          .image = std::move(ownership),
                                          .key = ownership_key(static_cast<int>(report.nodes))});
    run.blocks.push_back(viz::SvgFigure{.caption = "when each processor traced each tile", .svg = tiles});
    page.sections.push_back(std::move(run));
    written.push_back(outputs.write_text(files.report_html, viz::html_report(page)));
  }
  outputs.keep();
  return written;
}

}  // namespace app
