// `vmpray sweep nodes|cache`: the paper's experiments, one command each.
//
//   sweep nodes  Table 2: predicted synthesis time, speedup and efficiency
//                against the number of processors, for each topology asked.
//   sweep cache  Figure 8: efficiency, miss ratio and page communications
//                against the cache size (pages) for one machine.
// Each writes DIR/<kind>.csv, DIR/<kind>.json, DIR/<kind>.svg (all panels),
// one PNG per panel and DIR/<kind>.html (table + plots), and prints the table.
// Every point is a deterministic virtual-time run; T1 (for speedup and
// efficiency) is the one-node run of the same scene under the same model.
// Points run side by side on --jobs threads, no more than fit in the memory
// together; the tables do not depend on how many, except for the wall time
// each point took. A machine that does not fit alone is refused before any
// run, as a render's is (app/render/memory_check.hpp).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "app/experiments/points.hpp"
#include "app/render/options.hpp"
#include "app/render/output_files.hpp"
#include "app/viz/plot.hpp"

namespace app {

struct SweepOptions {
  enum class Kind { nodes, cache };
  Kind kind = Kind::nodes;
  std::string scene = "teapot";
  int size = 64;                          // image side in pixels
  std::uint32_t page_size = tracer::BuildOptions{}.page_size;
  std::vector<std::string> topologies{"hypercube"};
  std::vector<std::size_t> nodes{1, 2, 4, 8, 16, 32, 64};  // sweep nodes: the axis; cache: the first
  std::vector<std::uint32_t> cache_pages;  // sweep cache: the axis; nodes: the first (empty: default)
  nodes::Farming farming = paper_farming;
  nodes::CostModel model = nodes::ipsc2_profile();
  tracer::Accel accel = tracer::Accel::bvh;
  tracer::BvhLayout bvh_layout = tracer::BvhLayout::treelet;
  tracer::TraceOptions trace;             // --shadow-rays
  double fit_seconds = 0;                 // > 0: fit model.unit so T1 takes this long
  std::filesystem::path out_dir;          // default: sweep-<kind>
  unsigned jobs = 1;                      // points run side by side (--jobs 0: one per core)
  bool quiet = false;
};

// Of the sweep JSON: raised whenever a field changes meaning or goes away.
inline constexpr int sweep_schema_version = 1;

struct SweepTable {
  SweepOptions::Kind kind = SweepOptions::Kind::nodes;
  std::string scene;
  int width = 0, height = 0;
  std::uint32_t page_count = 0;
  std::string tracing;        // "bvh, shadow rays facing": what the counted work was
  std::string farming;        // "dynamic schedule, grain 4, prefetch 0, scanline order": how it was handed out
  nodes::CostModel model;
  double serial_seconds = 0;  // T1
  std::vector<ExperimentPoint> points;
  std::vector<std::string> command_line;  // as typed: "vmpray", "sweep", then the options; empty: not known
};

// argv[0] is "sweep". Throws UsageError (app/render/usage_error.hpp) for a bad command line.
SweepOptions parse_sweep_options(int argc, const char* const argv[]);
std::string sweep_usage();
// What `vmpray sweep --help` says, in pieces, for the manual page: the kinds
// of sweep, what a sweep does, and its options (app/render/options.hpp's OptionGroup).
struct SweepKindDoc {
  std::string name, description;
};
std::vector<SweepKindDoc> sweep_kinds();
std::string sweep_summary();
OptionGroup sweep_option_group();

SweepTable run_sweep(const SweepOptions& options, std::ostream* progress);

std::string sweep_csv(const SweepTable& table);
std::string sweep_json(const SweepTable& table);
// The plots a sweep draws: time, speedup and efficiency against processors
// (nodes), or efficiency, miss ratio and page communications against the
// cache (cache); one series per kind of topology, plus the paper's times
// and the ideal speedup where they apply.
std::vector<viz::LinePlot> sweep_plots(const SweepTable& table);
// Writes csv, json, svg, png panels and html into dir, adding each to
// `outputs` (and dir first, if it makes it): the caller keeps them once its
// command has finished. Returns the files written. Throws std::runtime_error
// naming the path if one cannot be written.
std::vector<std::filesystem::path> write_sweep(const SweepTable& table, const std::filesystem::path& dir,
                                               OutputFiles& outputs);

// The whole subcommand: exit status 0, 1 (run error) or 2 (usage, or a
// machine too large for the memory), errors one line on stderr.
int sweep_main(int argc, const char* const argv[]);

}  // namespace app
