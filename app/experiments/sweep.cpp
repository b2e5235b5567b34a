// `vmpray sweep`: option parsing, the runs, and the tables, plots and page
// they produce (see sweep.hpp).
#include "app/experiments/sweep.hpp"

#include <boost/program_options.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>

#include "app/experiments/output_check.hpp"
#include "app/render/cpu_count.hpp"
#include "app/render/machine_run.hpp"
#include "app/render/memory_check.hpp"
#include "app/render/options.hpp"
#include "app/render/scene_input.hpp"
#include "app/render/timing_options.hpp"
#include "topology/spec.hpp"

namespace app {

namespace po = boost::program_options;

namespace {

// The values of a swept axis, in increasing order (a plot's line runs along
// them); a value listed twice is an error, not a second run.
template <class T>
std::vector<T> parse_list(const std::string& text, const std::string& option) {
  std::vector<T> values;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ',');) {
    std::size_t used = 0;
    long long v = -1;
    try {
      v = std::stoll(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || v < 1 || static_cast<unsigned long long>(v) > std::numeric_limits<T>::max())
      throw UsageError(option + ": expected positive integers, got '" + item + "'");
    values.push_back(static_cast<T>(v));
  }
  if (values.empty()) throw UsageError(option + ": empty list");
  std::sort(values.begin(), values.end());
  if (const auto twice = std::adjacent_find(values.begin(), values.end()); twice != values.end())
    throw UsageError(option + ": " + std::to_string(*twice) + " is listed twice");
  return values;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ',');)
    if (!item.empty()) parts.push_back(item);
  return parts;
}

// The sweep's own options as typed, and those it shares with the render
// (app/render/options.hpp, timing_options.hpp) with the sweep's defaults: the paper's
// dynamic scanline farming of small tiles, asked for when idle.
struct RawSweep {
  std::string kind, topologies = "hypercube", nodes, cache, out;
  std::int64_t size = 64, jobs = 0;
  SharedChoice shared{.grain = paper_farming.grain,
                      .prefetch = paper_farming.prefetch,
                      .schedule = nodes::schedule_name(paper_farming.schedule),
                      .pixel_order = nodes::pixel_order_name(paper_farming.pixel_order)};
  TimingChoice model;
};

// One option a line, as Boost's examples lay them out.
// clang-format off
po::options_description describe(SweepOptions& o, RawSweep& raw) {
  po::options_description d("Sweep options");
  d.add_options()
      ("help,h", "show this help and exit")
      ("scene", po::value(&o.scene), "scene: NFF file or built-in (teapot, mountain, rings4, ...)")
      ("size", po::value(&raw.size), "image width and height in pixels (default 64; the paper: 512)")
      ("topology", po::value(&raw.topologies), "topologies, comma-separated (default hypercube)")
      ("nodes", po::value(&raw.nodes), "processor counts, comma-separated (nodes: default 1,2,...,64; cache: 16)")
      ("cache-pages", po::value(&raw.cache), "cache sizes in pages, comma-separated (cache: the axis)");
  add_farming_options(d, raw.shared);
  add_database_options(d, raw.shared);
  add_model_options(d, raw.model);
  d.add_options()
      ("fit-seconds", po::value(&o.fit_seconds), "fit the compute unit so the one-node run takes this long")
      ("out", po::value(&raw.out), "output directory (default sweep-KIND)")
      ("jobs,j", po::value(&raw.jobs), "runs side by side, each on a thread of its own, as many as fit in the memory (0, the default: one per core)")
      ("quiet,q", po::bool_switch(&o.quiet), "print nothing but errors");
  return d;
}
// clang-format on

// Every machine of the sweep exists, and the machine's own rules for what
// every run shares hold, before the first run.
void check_machines(const SweepOptions& o, bool nodes_given) {
  for (const std::string& topology : o.topologies)
    for (const std::size_t n : o.nodes) {
      try {
        topology::parse_topology(topology, n);
      } catch (const std::invalid_argument& e) {
        if (!nodes_given && topology.find(':') != std::string::npos)
          throw UsageError("--topology: " + topology + " has a size of its own, which the default --nodes list "
                           "does not fit; give --nodes with its node count, or the bare kind");
        throw UsageError(std::string("--topology: ") + e.what());
      }
      check_grid_shape(topology, n);
    }
  nodes::MachineOptions machine;
  machine.farming = o.farming;
  try {
    nodes::check_options(machine, o.page_size);
  } catch (const nodes::OptionError& e) {
    throw usage_error(e);
  }
}

void check_sweep(SweepOptions& o, const RawSweep& raw, const po::variables_map& vm) {
  if (raw.kind == "nodes") o.kind = SweepOptions::Kind::nodes;
  else if (raw.kind == "cache") o.kind = SweepOptions::Kind::cache;
  else throw UsageError("expected 'nodes' or 'cache' after 'sweep', got '" + raw.kind + "'");
  o.size = in_range<int>(raw.size, 1, 4096, "--size");
  const DatabaseChoice database = parse_database(raw.shared);
  o.page_size = database.page_size;
  o.accel = database.accel;
  o.bvh_layout = database.bvh_layout;
  o.trace.shadow_rays_to_all_lights = database.shadow_rays_all;
  o.farming = parse_farming(raw.shared, vm);
  o.jobs = in_range<unsigned>(raw.jobs, 0, 1024, "--jobs");
  if (o.jobs == 0) o.jobs = usable_cpus();
  if (vm.count("fit-seconds") && !(o.fit_seconds > 0 && std::isfinite(o.fit_seconds)))
    throw UsageError("--fit-seconds: expected a finite number of seconds above 0");
  o.topologies = split(raw.topologies);
  if (o.topologies.empty()) throw UsageError("--topology: empty list");
  for (auto t = o.topologies.begin(); t != o.topologies.end(); ++t)
    if (std::find(o.topologies.begin(), t, *t) != t) throw UsageError("--topology: " + *t + " is listed twice");
  // Given, a list must hold values: an empty one is not the default.
  const bool nodes_given = vm.count("nodes") > 0, cache_given = vm.count("cache-pages") > 0;
  if (nodes_given) o.nodes = parse_list<std::size_t>(raw.nodes, "--nodes");
  else if (o.kind == SweepOptions::Kind::cache) o.nodes = {16};
  if (cache_given) o.cache_pages = parse_list<std::uint32_t>(raw.cache, "--cache-pages");
  else if (o.kind == SweepOptions::Kind::cache) o.cache_pages = {8, 16, 32, 64, 128, 256, 512};
  // The other axis is one value: a list there would be cut to its first item.
  if (o.kind == SweepOptions::Kind::cache && o.nodes.size() > 1)
    throw UsageError("--nodes: a cache sweep runs one machine size, got " + raw.nodes);
  if (o.kind == SweepOptions::Kind::nodes && o.cache_pages.size() > 1)
    throw UsageError("--cache-pages: a nodes sweep runs one cache size, got " + raw.cache);
  check_machines(o, nodes_given);
  o.out_dir = raw.out.empty() ? "sweep-" + raw.kind : raw.out;
  // Found out now rather than after the runs, when the tables are written.
  check_writable_directory("--out", o.out_dir);
}

tracer::Database load_database(const SweepOptions& o) {
  Options render;
  render.scene = o.scene;
  render.width = o.size;
  render.height = o.size;
  render.page_size = o.page_size;
  render.accel = o.accel;
  render.bvh_layout = o.bvh_layout;
  return tracer::build_database(load_scene(render), build_options(render));
}

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
}

}  // namespace

SweepOptions parse_sweep_options(int argc, const char* const argv[]) {
  SweepOptions o;
  RawSweep raw;
  po::options_description all = describe(o, raw);
  all.add_options()("kind", po::value(&raw.kind));
  po::positional_options_description positional;
  positional.add("kind", 1).add("scene", 1);
  const po::variables_map vm = read_command_line(argc, argv, all, positional);
  if (vm.count("help")) throw UsageError("help");
  check_sweep(o, raw, vm);
  o.model = cost_model_from(raw.model.profile, raw.model.costs);
  return o;
}

std::string sweep_usage() {
  SweepOptions o;
  RawSweep raw;
  std::ostringstream out;
  out << "Usage: vmpray sweep nodes|cache [SCENE] [options]\n";
  for (const SweepKindDoc& kind : sweep_kinds()) out << "  " << kind.name << ": " << kind.description << "\n";
  out << sweep_summary() << "\n" << describe(o, raw);
  return out.str();
}

std::vector<SweepKindDoc> sweep_kinds() {
  return {{"nodes", "predicted synthesis time, speedup and efficiency against processors (Table 2)"},
          {"cache", "efficiency, miss ratio and page communications against cache size (Figure 8)"}};
}

std::string sweep_summary() {
  return "Runs the machine in virtual time (deterministic) and writes CSV, JSON, SVG, PNG and HTML.\n";
}

OptionGroup sweep_option_group() {
  SweepOptions o;
  RawSweep raw;
  return option_group(describe(o, raw));
}

namespace {

// T1's setup (one node, the fitted unit if asked), then the table's points
// in its order.
std::vector<ExperimentSetup> sweep_setups(const SweepOptions& o, const tracer::Database& db) {
  ExperimentSetup setup;
  setup.farming = o.farming;
  setup.model = o.model;
  setup.trace = o.trace;
  if (o.fit_seconds > 0) setup.model.unit = fit_unit(db, setup, o.fit_seconds, o.jobs);
  if (!o.cache_pages.empty()) setup.cache_pages = o.cache_pages.front();
  std::vector<ExperimentSetup> setups{setup};
  const bool by_nodes = o.kind == SweepOptions::Kind::nodes;
  for (const std::string& topology : o.topologies) {
    const std::size_t count = by_nodes ? o.nodes.size() : o.cache_pages.size();
    for (std::size_t i = 0; i < count; ++i) {
      setup.topology = topology::parse_topology(topology, by_nodes ? o.nodes[i] : o.nodes.front());
      if (!by_nodes) setup.cache_pages = o.cache_pages[i];
      setups.push_back(setup);
    }
  }
  return setups;
}

}  // namespace

SweepTable run_sweep(const SweepOptions& o, std::ostream* progress) {
  const tracer::Database db = load_database(o);
  SweepTable table;
  table.kind = o.kind;
  table.scene = db.header.scene_name.empty() ? o.scene : db.header.scene_name;
  table.width = db.header.camera.width;
  table.height = db.header.camera.height;
  table.page_count = db.header.page_count;
  table.tracing = accel_description(o.accel, o.bvh_layout) + ", shadow rays " +
                  (o.trace.shadow_rays_to_all_lights ? "all" : "facing");
  const nodes::Farming& f = o.farming;
  table.farming = std::string(nodes::schedule_name(f.schedule)) + " schedule" +
                  (f.schedule == nodes::Schedule::static_split ? "" : ", grain " + std::to_string(f.grain)) +
                  ", prefetch " + std::to_string(f.prefetch) + ", " + nodes::pixel_order_name(f.pixel_order) +
                  " order";
  const std::vector<ExperimentSetup> setups = sweep_setups(o, db);
  table.model = setups.front().model;
  // A machine too large for the memory is refused before any runs; runs go
  // side by side only as far as they fit together.
  std::vector<nodes::MachineOptions> machines;
  for (const ExperimentSetup& s : setups) machines.push_back(machine_options(s));
  const unsigned jobs = jobs_that_fit(machines, o.size, o.size, db.header.page_count, db.header.page_size, o.jobs,
                                     memory_limit());
  // Progress in the table's order; efficiency needs T1, which comes first.
  double serial_seconds = 0;
  const auto done = [&](std::size_t index, const ExperimentPoint& p) {
    if (index == 0) {
      serial_seconds = p.predicted_seconds;
      return;
    }
    if (!progress) return;
    ExperimentPoint shown = p;
    shown.serial_seconds = serial_seconds;
    *progress << p.topology << " N=" << p.nodes << " cache=" << p.cache_pages << ": "
              << paper_duration(p.predicted_seconds) << ", efficiency " << fixed(100 * shown.efficiency(), 1)
              << "%, miss ratio " << fixed(100 * p.miss_ratio, 2) << "% (wall " << fixed(p.wall_seconds, 1)
              << " s)\n";
  };
  const std::vector<ExperimentPoint> points = run_points(db, setups, jobs, done);
  table.serial_seconds = points.front().predicted_seconds;
  table.points.assign(points.begin() + 1, points.end());
  for (ExperimentPoint& p : table.points) p.serial_seconds = table.serial_seconds;
  return table;
}

}  // namespace app
