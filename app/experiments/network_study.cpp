// `vmpray network`: options, the curves' runs, and the table, plots and page
// they produce (see network_study.hpp).
#include "app/experiments/network_study.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/program_options.hpp>

#include "app/experiments/machine_pictures.hpp"
#include "app/experiments/output_check.hpp"
#include "app/render/cpu_count.hpp"
#include "app/render/machine_summary.hpp"
#include "app/render/output_files.hpp"
#include "app/render/progress.hpp"
#include "app/render/run_report.hpp"
#include "app/render/scene_input.hpp"
#include "app/render/timing_options.hpp"
#include "app/viz/html_report.hpp"
#include "app/viz/machine_drawing.hpp"
#include "app/viz/plot.hpp"
#include "app/viz/plot_raster.hpp"
#include "nodes/machine/recorder.hpp"
#include "topology/spec.hpp"

namespace app {

namespace po = boost::program_options;

namespace {

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ',');) parts.push_back(item);
  return parts;
}

struct RawNetwork {
  std::string topologies = "hypercube:6,torus:8x8,mesh:8x8,ring:64,complete:64", patterns = "uniform",
              loads = "0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1,1.1,1.2", out = "network";
  std::string scene = "rings4";
  std::int64_t payload = 64, buffers = 4, jobs = 0, seed = 1, scene_size = 64;
  double hotspot = 0.2, links_at = 0.5;
  TimingChoice model;
};

// clang-format off
po::options_description describe(NetworkStudyOptions& o, RawNetwork& raw) {
  po::options_description d("Network options");
  d.add_options()
      ("help,h", "show this help and exit")
      ("topology", po::value(&raw.topologies),
       "full specs, comma-separated (default hypercube:6,torus:8x8,mesh:8x8,ring:64,complete:64)")
      ("pattern", po::value(&raw.patterns),
       "traffic patterns, comma-separated (default uniform): uniform, transpose, bit-complement, bit-reversal, "
       "shuffle, tornado, neighbour, hotspot, render (see below)")
      ("loads", po::value(&raw.loads),
       "offered loads as fractions of each topology's channel-load bound, comma-separated, increasing (default "
       "0.1,0.2,...,1.2)")
      ("payload", po::value(&raw.payload), "bytes a packet carries, 1..1048576 (default 64)")
      ("buffers", po::value(&raw.buffers), "packets per link queue, 1..64 (default 4)")
      ("hotspot", po::value(&raw.hotspot), "hotspot: the share of packets sent to node 0, above 0 and below 1 (default 0.2)")
      ("seed", po::value(&raw.seed), "seed of the packets' times and destinations (default 1)")
      ("scene", po::value(&raw.scene),
       "render: the scene whose render's packets each topology is offered, a built-in or an NFF file "
       "(default rings4)")
      ("scene-size", po::value(&raw.scene_size), "render: its image's pixels a side, 1..1024 (default 64)")
      ("links-at", po::value(&raw.links_at),
       "draw each topology's links by their traffic at the load of --loads nearest this one, under the first "
       "pattern (default 0.5)");
  add_model_options(d, raw.model);
  d.add_options()
      ("out", po::value(&raw.out), "output directory (default network)")
      ("jobs,j", po::value(&raw.jobs), "points run side by side, each on a thread of its own (0, the default: one per core)")
      ("quiet,q", po::bool_switch(&o.quiet), "print nothing but errors");
  return d;
}
// clang-format on

std::vector<double> parse_loads(const std::string& text) {
  std::vector<double> loads;
  for (const std::string& item : split(text)) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || item.empty() || !(v > 0) || !std::isfinite(v) || v > 100)
      throw UsageError("--loads: expected fractions of the bound above 0 (at most 100), got '" + item + "'");
    if (!loads.empty() && v <= loads.back())
      throw UsageError("--loads: expected increasing loads, got " + item + " after " + std::to_string(loads.back()));
    loads.push_back(v);
  }
  if (loads.empty()) throw UsageError("--loads: empty list");
  return loads;
}

template <class T>
T whole_in(std::int64_t v, std::int64_t low, std::int64_t high, const char* option) {
  if (v < low || v > high)
    throw UsageError(std::string(option) + ": expected " + std::to_string(low) + ".." + std::to_string(high) +
                     ", got " + std::to_string(v));
  return static_cast<T>(v);
}

void check_network(NetworkStudyOptions& o, const RawNetwork& raw) {
  const std::vector<std::string> specs = split(raw.topologies);
  if (specs.empty()) throw UsageError("--topology: empty list");
  for (auto t = specs.begin(); t != specs.end(); ++t) {
    if (t->empty()) throw UsageError("--topology: an empty item in '" + raw.topologies + "'");
    if (std::find(specs.begin(), t, *t) != t) throw UsageError("--topology: " + *t + " is listed twice");
  }
  o.patterns.clear();
  for (const std::string& name : split(raw.patterns)) {
    try {
      o.patterns.push_back(nodes::parse_traffic_pattern(name));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--pattern: ") + e.what());
    }
    if (std::count(o.patterns.begin(), o.patterns.end(), o.patterns.back()) > 1)
      throw UsageError("--pattern: " + name + " is listed twice");
  }
  if (o.patterns.empty()) throw UsageError("--pattern: empty list");
  o.topologies.clear();
  for (const std::string& spec : specs) {
    try {
      o.topologies.push_back(topology::parse_topology(spec));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--topology: ") + e.what());
    }
    const topology::Topology& t = o.topologies.back();
    for (const nodes::TrafficPattern p : o.patterns)
      if (const std::string why = nodes::pattern_unfit(p, t); !why.empty()) throw UsageError("--pattern: " + why);
  }
  o.loads = parse_loads(raw.loads);
  o.study.payload_bytes = whole_in<std::size_t>(raw.payload, 1, 1 << 20, "--payload");
  o.study.buffer_capacity = whole_in<std::size_t>(raw.buffers, 1, 64, "--buffers");
  o.study.seed = whole_in<std::uint32_t>(raw.seed, 0, UINT32_MAX, "--seed");
  o.scene = raw.scene;
  o.scene_size = whole_in<int>(raw.scene_size, 1, 1024, "--scene-size");
  if (std::count(o.patterns.begin(), o.patterns.end(), nodes::TrafficPattern::recorded) > 0) {
    Options render;  // read now, so that a bad scene is refused before any run
    render.scene = o.scene;
    render.quiet = true;
    render.width = render.height = o.scene_size;
    o.render_scene = std::make_shared<const tracer::Scene>(load_scene(render));
  }
  if (!(raw.hotspot > 0 && raw.hotspot < 1)) throw UsageError("--hotspot: expected a share above 0 and below 1");
  o.study.hotspot_fraction = raw.hotspot;
  if (!(raw.links_at > 0) || !std::isfinite(raw.links_at))
    throw UsageError("--links-at: expected a load above 0, as a fraction of the bound");
  o.links_at = raw.links_at;
  o.jobs = whole_in<unsigned>(raw.jobs, 0, 1024, "--jobs");
  if (o.jobs == 0) o.jobs = usable_cpus();
  o.out_dir = raw.out;
  check_writable_directory("--out", o.out_dir);
}

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
}

std::string microseconds(double seconds) { return fixed(seconds * 1e6, 1); }

}  // namespace

TopologyCost topology_cost(const topology::Topology& t) {
  TopologyCost c;
  c.spec = t.spec();
  c.nodes = t.size();
  std::size_t ports = 0;
  for (topology::NodeId n = 0; n < t.size(); ++n) {
    ports += t.degree(n);
    c.degree = std::max(c.degree, t.degree(n));
  }
  c.links = ports / 2;
  c.diameter = t.diameter();
  c.average_distance = t.average_distance();
  const std::size_t w = t.width(), h = t.height(), n = t.size();
  switch (t.kind()) {
    case topology::Kind::hypercube: c.bisection = n / 2; break;
    case topology::Kind::mesh: c.bisection = w >= h ? h : w; break;  // cut across the longer side
    case topology::Kind::torus: c.bisection = 2 * (w >= h ? h : w); break;  // and each row's wrap
    case topology::Kind::ring: c.bisection = n > 2 ? 2 : 1; break;
    case topology::Kind::complete: c.bisection = (n / 2) * (n - n / 2); break;
  }
  return c;
}

NetworkStudyOptions parse_network_options(int argc, const char* const argv[]) {
  NetworkStudyOptions o;
  RawNetwork raw;
  po::options_description all = describe(o, raw);
  const po::variables_map vm = read_command_line(argc, argv, all);
  if (vm.count("help")) throw UsageError("help");
  check_network(o, raw);
  o.model = cost_model_from(raw.model.profile, raw.model.costs);
  if (!o.model.link_model().enabled())
    throw UsageError("--cost: a network study needs a link cost: hop= or bw= above 0");
  o.study.link = o.model.link_model();
  return o;
}

std::string network_summary() {
  return "Offers each topology a traffic pattern at rising loads, in virtual time (deterministic), and measures "
         "packet latency (from creation, the wait at the source included, to delivery) and accepted throughput. "
         "Writes CSV, JSON, SVG, PNG and HTML.\n";
}

std::string network_usage() {
  NetworkStudyOptions o;
  RawNetwork raw;
  std::ostringstream out;
  out << "Usage: vmpray network [options]\n" << network_summary() << "\nPatterns:\n";
  std::istringstream lines(nodes::pattern_descriptions());
  for (std::string line; std::getline(lines, line);) out << "  " << line << "\n";
  out << "\n" << describe(o, raw);
  return out.str();
}

OptionGroup network_option_group() {
  NetworkStudyOptions o;
  RawNetwork raw;
  return option_group(describe(o, raw));
}

namespace {

// The mean distance of a pattern's packets on `t`: a fixed pattern's over
// the nodes that send, else the average distance.
double pattern_distance(const topology::Topology& t, nodes::TrafficPattern p) {
  const auto to = nodes::fixed_destinations(p, t);
  if (to.empty()) return t.average_distance();
  double sum = 0;
  std::size_t senders = 0;
  for (topology::NodeId n = 0; n < to.size(); ++n)
    if (to[n] != n) sum += t.distance(n, to[n]), ++senders;
  return senders ? sum / static_cast<double>(senders) : 0;
}

// Every point of every curve, with its bound and zero-load latency, not run;
// the render pattern's traffic recorded once a topology.
void plan_points(const NetworkStudyOptions& o, NetworkTable& table, std::ostream* progress) {
  const double message = nodes::zero_load_latency(o.study.link, o.study.payload_bytes, 0);
  for (const topology::Topology& t : o.topologies) {
    table.costs.push_back(topology_cost(t));
    for (const nodes::TrafficPattern p : o.patterns) {
      std::shared_ptr<const nodes::RecordedTraffic> recorded;
      double load_at_one = 0, zero_load = 0;
      if (p == nodes::TrafficPattern::recorded) {
        if (progress) *progress << "network: recording a render of " << o.scene << " on " << t.spec() << "\n";
        recorded = std::make_shared<const nodes::RecordedTraffic>(record_render_traffic(o, t));
        load_at_one = nodes::recorded_channel_load(t, *recorded, o.study.link, o.study.payload_bytes);
        zero_load = nodes::recorded_zero_load_latency(t, *recorded, o.study.link);
      } else {
        load_at_one = nodes::max_channel_load(t, p, o.study.hotspot_fraction);
        zero_load = (pattern_distance(t, p) + 1) * message;
      }
      const double bound = 1.0 / (message * load_at_one);
      for (const double load : o.loads)
        table.points.push_back({.topology = t.spec(), .pattern = p, .load = load, .bound = bound,
                                .zero_load = zero_load, .recorded = recorded, .saturated = false, .result = {},
                                .wall_seconds = 0});
    }
  }
}

// Runs the points on `jobs` threads, each taking the next point not run;
// the first failure stops the others' taking and is rethrown.
void run_points(const NetworkStudyOptions& o, std::vector<NetworkPoint>& points, std::ostream* progress) {
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex report;
  std::exception_ptr failure;
  const auto work = [&] {
    for (std::size_t i; (i = next++) < points.size();) {
      NetworkPoint& p = points[i];
      try {
        const auto start = std::chrono::steady_clock::now();
        nodes::LoadStudyOptions study = o.study;
        study.recorded = p.recorded;
        p.result = nodes::run_load(study_topology(o, p.topology), p.pattern, p.load * p.bound, study);
        p.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        p.saturated = p.result.accepted < 0.95 * p.result.offered || p.result.mean_latency > 10 * p.zero_load;
      } catch (...) {
        const std::lock_guard lock(report);
        if (!failure) failure = std::current_exception();
        next = points.size();
      }
      const std::lock_guard lock(report);
      if (progress) *progress << "\rnetwork: " << ++done << " of " << points.size() << " points" << std::flush;
    }
  };
  std::vector<std::thread> threads;
  for (unsigned j = 1; j < std::min<std::size_t>(o.jobs, points.size()); ++j) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (progress) *progress << "\n";
  if (failure) std::rethrow_exception(failure);
}

}  // namespace

const topology::Topology& study_topology(const NetworkStudyOptions& o, const std::string& spec) {
  for (const topology::Topology& t : o.topologies)
    if (t.spec() == spec) return t;
  throw std::logic_error("network study: no topology " + spec + " in the options");
}

nodes::RecordedTraffic record_render_traffic(const NetworkStudyOptions& o, const topology::Topology& t) {
  if (!o.render_scene) throw std::logic_error("record_render_traffic: no scene read");
  Options render;
  render.width = render.height = o.scene_size;
  nodes::MachineOptions m;
  m.topology = t;
  m.threads.count = 1;
  m.timing = o.model;
  m.observe.record = true;
  m.observe.record_packets = std::numeric_limits<std::uint64_t>::max();
  const nodes::MachineResult r = nodes::run_machine(tracer::build_database(*o.render_scene, build_options(render)), m);
  nodes::RecordedTraffic traffic;
  traffic.by_source.resize(t.size());
  for (const nodes::PacketTrace& p : r.report.recording->packets)  // by injection time: each source's in its order
    if (p.hops() > 0) traffic.by_source[p.route.front()].push_back({p.route.back(), p.bytes});
  return traffic;
}

NetworkTable run_network_study(const NetworkStudyOptions& o, std::ostream* progress) {
  NetworkTable table;
  table.options = o;
  plan_points(o, table, progress);
  run_points(o, table.points, progress);
  return table;
}

std::string network_csv(const NetworkTable& t) {
  std::ostringstream out;
  out << "topology,pattern,load,offered_per_node_s,accepted_per_node_s,mean_latency_us,p50_latency_us,"
         "p99_latency_us,max_latency_us,zero_load_latency_us,mean_hops,in_flight,packets,saturated,wall_s\n";
  for (const NetworkPoint& p : t.points) {
    const nodes::LoadResult& r = p.result;
    out << p.topology << ',' << nodes::pattern_name(p.pattern) << ',' << p.load << ',' << fixed(r.offered, 2) << ','
        << fixed(r.accepted, 2) << ',' << microseconds(r.mean_latency) << ',' << microseconds(r.p50_latency) << ','
        << microseconds(r.p99_latency) << ',' << microseconds(r.max_latency) << ',' << microseconds(p.zero_load)
        << ',' << fixed(r.mean_hops, 3) << ',' << fixed(r.mean_in_flight, 2) << ',' << r.created << ','
        << (p.saturated ? "yes" : "no") << ',' << fixed(p.wall_seconds, 2) << '\n';
  }
  return out.str();
}

std::string network_json(const NetworkTable& t) {
  Json topologies = Json::array();
  for (const TopologyCost& c : t.costs)
    topologies.push_back({{"topology", c.spec},
                          {"nodes", c.nodes},
                          {"links", c.links},
                          {"degree", c.degree},
                          {"diameter", c.diameter},
                          {"average_distance", c.average_distance},
                          {"bisection_links", c.bisection}});
  Json points = Json::array();
  for (const NetworkPoint& p : t.points) {
    const nodes::LoadResult& r = p.result;
    points.push_back({{"topology", p.topology},
                      {"pattern", nodes::pattern_name(p.pattern)},
                      {"load", p.load},
                      {"bound_per_node_s", p.bound},
                      {"offered_per_node_s", r.offered},
                      {"accepted_per_node_s", r.accepted},
                      {"latency_s", {{"mean", r.mean_latency}, {"p50", r.p50_latency}, {"p99", r.p99_latency},
                                     {"max", r.max_latency}, {"zero_load", p.zero_load}}},
                      {"mean_hops", r.mean_hops},
                      {"mean_in_flight", r.mean_in_flight},
                      {"packets", {{"created", r.created}, {"delivered", r.delivered},
                                   {"misdelivered", r.misdelivered}, {"measured", r.measured}}},
                      {"saturated", p.saturated},
                      {"virtual_end_s", r.end_seconds},
                      {"wall_s", p.wall_seconds}});
  }
  Json recorded = Json::object();  // the render pattern's packets a topology
  for (const NetworkPoint& p : t.points)
    if (p.recorded) recorded[p.topology] = p.recorded->packets();
  const Json j = {{"schema_version", network_schema_version},
                  {"command_line", t.command_line},
                  {"render", {{"scene", t.options.scene},
                              {"pixels_a_side", t.options.scene_size},
                              {"recorded_packets", recorded}}},
                  {"payload_bytes", t.options.study.payload_bytes},
                  {"buffer_packets", t.options.study.buffer_capacity},
                  {"hotspot_share", t.options.study.hotspot_fraction},
                  {"seed", t.options.study.seed},
                  {"cost_model", cost_model_json(t.options.model)},
                  {"topologies", topologies},
                  {"points", points}};
  return dump_json(j, 2) + "\n";
}

namespace {

// Per pattern: mean latency against offered load, and accepted against
// offered, one line a topology.
std::vector<viz::LinePlot> network_plots(const NetworkTable& t) {
  std::vector<viz::LinePlot> plots;
  for (const nodes::TrafficPattern pattern : t.options.patterns) {
    viz::LinePlot latency{.title = std::string(nodes::pattern_name(pattern)) + " traffic: latency",
                          .x_label = "offered load (fraction of the bound)",
                          .y_label = "mean latency (us)",
                          .y_scale = viz::AxisScale::log10};
    viz::LinePlot accepted{.title = std::string(nodes::pattern_name(pattern)) + " traffic: throughput",
                           .x_label = "offered load (fraction of the bound)",
                           .y_label = "accepted / bound"};
    for (const topology::Topology& network : t.options.topologies) {
      const std::string spec = network.spec();
      viz::Series l{.name = spec}, a{.name = spec};
      for (const NetworkPoint& p : t.points) {
        if (p.pattern != pattern || p.topology != spec) continue;
        l.points.push_back({p.load, p.result.mean_latency * 1e6});
        a.points.push_back({p.load, p.result.accepted / p.bound});
      }
      latency.series.push_back(l);
      accepted.series.push_back(a);
    }
    plots.push_back(latency);
    plots.push_back(accepted);
  }
  return plots;
}

viz::Table cost_table(const NetworkTable& t) {
  viz::Table table{.caption = "What each topology costs",
                   .header = {"topology", "nodes", "links", "degree", "diameter", "average distance",
                              "bisection links", "uniform bound (packets/node/s)"}};
  const double message = nodes::zero_load_latency(t.options.study.link, t.options.study.payload_bytes, 0);
  for (const TopologyCost& c : t.costs)
    table.rows.push_back({c.spec, std::to_string(c.nodes), std::to_string(c.links), std::to_string(c.degree),
                          std::to_string(c.diameter), fixed(c.average_distance, 3), std::to_string(c.bisection),
                          fixed(1.0 / (message * nodes::max_channel_load(study_topology(t.options, c.spec),
                                                                         nodes::TrafficPattern::uniform, 0)),
                                1)});
  return table;
}

viz::Table points_table(const NetworkTable& t) {
  viz::Table table{.caption = "Every point (latency in microseconds, from creation to delivery)",
                   .header = {"topology", "pattern", "load", "offered", "accepted", "mean", "p50", "p99", "max",
                              "zero-load", "hops", "saturated"}};
  for (const NetworkPoint& p : t.points)
    table.rows.push_back({p.topology, nodes::pattern_name(p.pattern), fixed(p.load, 2), fixed(p.result.offered, 1),
                          fixed(p.result.accepted, 1), microseconds(p.result.mean_latency),
                          microseconds(p.result.p50_latency), microseconds(p.result.p99_latency),
                          microseconds(p.result.max_latency), microseconds(p.zero_load),
                          fixed(p.result.mean_hops, 2), p.saturated ? "yes" : "no"});
  return table;
}

// Each topology's links drawn by what they carried at the load nearest
// --links-at, under the first pattern.
std::vector<viz::MachineDrawing> link_pictures(const NetworkTable& t) {
  std::vector<viz::MachineDrawing> pictures;
  for (const TopologyCost& c : t.costs) {
    const NetworkPoint* nearest = nullptr;
    for (const NetworkPoint& p : t.points)
      if (p.topology == c.spec && p.pattern == t.options.patterns.front() &&
          (!nearest || std::abs(p.load - t.options.links_at) < std::abs(nearest->load - t.options.links_at)))
        nearest = &p;
    viz::MachineDrawing m = machine_shape(study_topology(t.options, c.spec));
    m.title = c.spec + ": link traffic, " + nodes::pattern_name(nearest->pattern) + " traffic at load " +
              fixed(nearest->load, 2) + " of the bound";
    m.nodes.assign(c.nodes, viz::NodeWork{});
    for (const nodes::LinkStats& l : nearest->result.links)
      m.links.push_back(viz::LinkTraffic{static_cast<int>(l.from), static_cast<int>(l.to), l.packets, l.bytes});
    pictures.push_back(std::move(m));
  }
  return pictures;
}

std::vector<std::filesystem::path> write_network(const NetworkTable& t, OutputFiles& outputs) {
  const std::filesystem::path& dir = t.options.out_dir;
  if (!std::filesystem::exists(dir)) outputs.add(dir);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error(dir.string() + ": cannot create the directory: " + error.message());
  const auto plots = network_plots(t);
  std::vector<std::filesystem::path> files;
  files.push_back(outputs.write_text(dir / "network.csv", network_csv(t)));
  files.push_back(outputs.write_text(dir / "network.json", network_json(t)));
  files.push_back(outputs.write_text(dir / "network.svg", viz::plots_svg(plots, 2)));
  for (std::size_t i = 0; i < plots.size(); ++i)
    files.push_back(outputs.write(dir / ("network-" + std::to_string(i + 1) + "-plot.png"),
                                  [&](const auto& path) { viz::plot_image(plots[i]).write_image(path.string()); }));
  viz::Report report{.title = "vmpray network", .version = "vmpray " VMPRAY_VERSION, .command_line = t.command_line};
  viz::Section section{.heading = std::to_string(t.options.study.payload_bytes) + "-byte packets, " +
                                  std::to_string(t.options.study.buffer_capacity) + " per link queue, " +
                                  t.options.model.describe()};
  section.blocks.push_back(viz::Paragraph{
      "Load 1 offers the busiest link of the topology, under its own routing and with the delivery channels "
      "counted, its capacity of one packet a message time. A point is saturated when it accepts less than 95% "
      "of what is offered or its mean latency passes 10 times the zero-load latency."});
  section.blocks.push_back(cost_table(t));
  section.blocks.push_back(viz::SvgFigure{.caption = "latency and throughput against offered load",
                                          .svg = viz::plots_svg(plots, 2)});
  section.blocks.push_back(points_table(t));
  const auto pictures = link_pictures(t);
  for (std::size_t i = 0; i < pictures.size(); ++i) {
    const std::string svg = viz::machine_svg(pictures[i]);
    files.push_back(outputs.write_text(dir / ("network-links-" + std::to_string(i + 1) + ".svg"), svg));
    section.blocks.push_back(viz::SvgFigure{.caption = pictures[i].title, .svg = svg});
  }
  report.sections.push_back(section);
  files.push_back(outputs.write_text(dir / "network.html", viz::html_report(report)));
  return files;
}

}  // namespace

int network_main(int argc, const char* const argv[]) {
  NetworkStudyOptions options;
  try {
    options = parse_network_options(argc, argv);
  } catch (const UsageError& e) {
    if (std::string(e.what()) == "help") {
      std::cout << network_usage();
      return std::cout.flush() ? 0 : 1;
    }
    std::cerr << "vmpray network: " << e.what() << " (see vmpray network --help)\n";
    return 2;
  }
  try {
    NetworkTable table = run_network_study(options, options.quiet || !stderr_is_terminal() ? nullptr : &std::cerr);
    table.command_line.assign(argv, argv + argc);
    table.command_line.insert(table.command_line.begin(), "vmpray");
    OutputPhase phase;
    const auto files = write_network(table, phase.files());
    if (!options.quiet) {
      std::cout << network_csv(table);
      std::cout << "link model " << table.options.model.describe() << "\n";
      std::cout << "wrote " << files.size() << " files in " << options.out_dir.string() << "\n";
    }
    return phase.finish(std::cout, "table");
  } catch (const std::exception& e) {
    std::cerr << "vmpray network: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace app
