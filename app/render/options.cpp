// Option parsing with Boost.Program_options; every failure becomes a one-line
// UsageError naming the option.
#include "app/render/options.hpp"

#include <algorithm>
#include <boost/program_options.hpp>
#include <sstream>

#include "app/render/cpu_count.hpp"
#include "nodes/machine/messages.hpp"
#include "topology/spec.hpp"
#include "topology/topology.hpp"
#include "tracer/generators.hpp"
#include "tracer/image.hpp"
#include "tracer/tessellate.hpp"

namespace app {
namespace po = boost::program_options;
namespace {

// Values that need checking or converting before they reach Options.
struct Raw {
  SharedChoice shared;  // the options a sweep takes too
  std::int64_t max_depth = 0, width = 0, height = 0, tessellate = 0;
  std::string topology, distribution, trace_kind;
  std::int64_t nodes = 0, threads = 0, cache_pages = 0, cache_kb = 0, workers = 0, trace_routes = 0,
               replay_packets = 0;
  TimingChoice timing;
};

// One option a line, as Boost's examples lay them out.
// clang-format off
po::options_description describe_render(Options& o, Raw& raw) {
  po::options_description d("Options");
  d.add_options()
      ("help,h", "show this help and exit")
      ("version", "show the version and exit")
      ("output,o", po::value(&o.output), "output image, .png or .ppm (default: SCENE.png)")
      ("stats", po::value(&o.stats_path), "write the report as JSON to this file (- for standard output, the text report then going to stderr)")
      ("spd-procedure", po::bool_switch(&o.spd_procedure),
       "SPD testing procedure: pixel-corner eye rays, depth 5, no adaptive cut-off");
  add_database_options(d, raw.shared);
  d.add_options()
      ("max-depth", po::value(&raw.max_depth)->default_value(5), "maximum ray depth (eye ray = 1)")
      ("width", po::value(&raw.width), "image width (default: the scene's)")
      ("height", po::value(&raw.height), "image height (default: the scene's)")
      ("tessellate", po::value(&raw.tessellate),
       ("tessellate spheres and cones into triangles at this resolution, 1.." +
        std::to_string(tracer::kMaxTessellation) + " (12 r^2 triangles a sphere, 8 r a cone)").c_str())
      ("quiet,q", po::bool_switch(&o.quiet), "no progress bar and no report")
      ("estimate-memory", po::bool_switch(&o.estimate_memory),
       "print the memory the run needs, as the check before every run counts it, and the limit it is held "
       "against; render nothing");
  return d;
}
// clang-format on

// One option a line, as Boost's examples lay them out.
// clang-format off
po::options_description describe_machine(Options& o, Raw& raw) {
  po::options_description d("Machine options (the image is the same for every setting)");
  d.add_options()
      ("single", po::bool_switch(&o.single),
       "render in this process with the whole database in memory, no machine (the options below but "
       "--threads are then errors)")
      ("topology", po::value(&raw.topology)->default_value("hypercube"),
       "hypercube, mesh, torus, ring or complete (with --nodes), or a full spec: "
       "hypercube:4, mesh:4x4, torus:4x4, ring:16, complete:16")
      ("nodes", po::value(&raw.nodes),
       ("processors, at most " + std::to_string(topology::max_nodes) + " (default 16, or the full spec's)").c_str())
      ("threads", po::value(&raw.threads)->default_value(0),
       "OS threads carrying the processors, 0..4096 (0: the CPUs this process may use, by its affinity and CPU "
       "quota, but at most one thread for every two pixel computers, --nodes x --workers-per-node, so that a "
       "processor waiting for a page leaves its thread another to run, and two for two or three nodes; never "
       "more than --nodes); with "
       "--single, threads tracing rows (at most the image's rows); the database is built on as many")
      ("cache-pages", po::value(&raw.cache_pages),
       "remote pages cached per node (default: 1/8 of the database, at least 64 pages)")
      ("cache-kb", po::value(&raw.cache_kb), "the cache per node in KB instead of pages");
  add_farming_options(d, raw.shared);
  d.add_options()
      ("workers-per-node", po::value(&raw.workers)->default_value(1),
       "pixel computers per processor")
      ("distribution", po::value(&raw.distribution)->default_value("modulo"),
       "page p on node p mod N (modulo), or consecutive runs of pages (block)")
      ("trace-routes", po::value(&raw.trace_routes)->default_value(0),
       "print the routes of the first N packets injected, hop by hop, 0..1048576 (of the kinds --trace-kind names)")
      ("trace-kind", po::value(&raw.trace_kind),
       "with --trace-routes: trace packets of these kinds only, comma-separated: work_request, work, stop, result, "
       "page_request, page_reply, worker_done, server_stop, server_done")
      ("tiles", po::value(&o.tiles_csv),
       "write a CSV row per tile: node, worker, first item, items, start and end seconds (wall, or virtual "
       "with --timing virtual), page requests and rays")
      ("replay", po::value(&o.replay_html),
       "write one self-contained HTML page that replays the run: nodes at work, packets hop by hop, the image "
       "filling in (over mpirun too: rank 0 gathers every rank's recording)")
      ("replay-packets", po::value(&raw.replay_packets)->default_value(100000),
       "with --replay: packets recorded hop by hop, 0..4194304, and the waits for pages and serves begun meanwhile; "
       "later ones are only counted (the page says so)")
      ("compare-serial", po::bool_switch(&o.compare_serial),
       "also run the 1-node machine; report speedup and efficiency T1/(N*TN)");
  add_timing_options(d, raw.timing, o.pictures);
  return d;
}
// clang-format on

// Width, height and tessellation are 0 (the scene's own) only when not given.
void check_render(Options& o, const Raw& raw, const po::variables_map& vm) {
  const DatabaseChoice database = parse_database(raw.shared);
  o.accel = database.accel;
  o.bvh_layout = database.bvh_layout;
  o.shadow_rays_all = database.shadow_rays_all;
  o.page_size = database.page_size;
  o.max_depth = in_range<int>(raw.max_depth, 1, 64, "--max-depth");
  if (vm.count("width")) o.width = in_range<int>(raw.width, 1, 16384, "--width");
  if (vm.count("height")) o.height = in_range<int>(raw.height, 1, 16384, "--height");
  if (vm.count("tessellate")) o.tessellate = in_range<int>(raw.tessellate, 1, tracer::kMaxTessellation, "--tessellate");
  if (!vm.count("output")) o.output = default_output(o.scene);
}

// A bare kind takes --nodes (default 16); a full spec stands alone or must agree.
void check_topology(nodes::MachineOptions& m, const Raw& raw, const po::variables_map& vm) {
  std::optional<std::size_t> nodes = 16;
  if (vm.count("nodes")) nodes = in_range<std::size_t>(raw.nodes, 1, topology::max_nodes, "--nodes");
  else if (raw.topology.find(':') != std::string::npos) nodes.reset();
  try {
    m.topology = topology::parse_topology(raw.topology, nodes);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--topology: ") + e.what());
  }
  if (nodes) check_grid_shape(raw.topology, *nodes);
}

// The cache's rules (one of the two, at least a page) are the machine's,
// checked with the others in check_machine.
void check_cache(Options& o, const Raw& raw, const po::variables_map& vm) {
  nodes::MachineOptions& m = o.machine;
  if (vm.count("cache-pages"))
    m.cache.pages = in_range<std::uint32_t>(raw.cache_pages, 1, UINT32_MAX, "--cache-pages");
  if (vm.count("cache-kb")) m.cache.kb = in_range<std::uint64_t>(raw.cache_kb, 1, std::int64_t(1) << 40, "--cache-kb");
}

void check_machine(Options& o, const Raw& raw, const po::variables_map& vm) {
  nodes::MachineOptions& m = o.machine;
  check_topology(m, raw, vm);
  check_cache(o, raw, vm);
  m.threads.count = in_range<unsigned>(raw.threads, 0, 4096, "--threads");
  m.farming = parse_farming(raw.shared, vm);
  m.shape.workers_per_node = as_field<int>(raw.workers, "--workers-per-node");
  m.observe.trace_routes = in_range<std::uint64_t>(raw.trace_routes, 0, 1 << 20, "--trace-routes");
  if (vm.count("trace-kind")) {
    if (m.observe.trace_routes == 0)
      throw UsageError("--trace-kind: chooses the packets --trace-routes N traces; give that too");
    m.observe.trace_kinds = parse_trace_kinds(raw.trace_kind);
  }
  if (raw.distribution == "modulo") m.shape.distribution = nodes::Distribution::modulo;
  else if (raw.distribution == "block") m.shape.distribution = nodes::Distribution::block;
  else throw UsageError("--distribution: expected modulo or block, got '" + raw.distribution + "'");
  m.timing = timing_from(raw.timing);
  // Options that would change nothing here are errors, as with --single.
  if (m.timing && o.compare_serial)
    throw UsageError("--compare-serial: a virtual-time run always reports speedup against the 1-node machine");
  // The tile CSV, the timeline and the report (which shows the timeline) need the tiles.
  m.observe.record_tiles = !o.tiles_csv.empty() || !o.pictures.timeline_svg.empty() || !o.pictures.report_html.empty();
  m.observe.record = !o.replay_html.empty();
  m.observe.record_packets = in_range<std::uint64_t>(raw.replay_packets, 0, 1 << 22, "--replay-packets");
  if (!vm["replay-packets"].defaulted() && !m.observe.record)
    throw UsageError("--replay-packets: bounds what --replay records; give that too");
  // The machine's own rules, now rather than after the scene is read.
  try {
    nodes::check_options(m, o.page_size);
  } catch (const nodes::OptionError& e) {
    throw usage_error(e);
  }
}

// --single renders in this process: an option of the machine but --threads,
// given with it, would be ignored.
void reject_machine_options(const po::options_description& machine, const po::variables_map& vm) {
  for (const auto& option : machine.options()) {
    const std::string& name = option->long_name();
    if (name != "single" && name != "threads" && vm.count(name) && !vm[name].defaulted())
      throw UsageError("--" + name + ": an option of the machine, but --single renders without one");
  }
}

// Each file option names a file, of the kind its writer makes: a name that
// is empty, or whose extension says another kind, is refused before the
// render rather than written under a misleading name after it.
void check_output_names(const Options& o, const po::variables_map& vm) {
  struct Named {
    const char* option;
    const std::string& path;
    std::vector<std::string> extensions;  // lower case; none: any name
  };
  const Named outputs[] = {
      {"output", o.output, {".png", ".ppm"}},
      {"stats", o.stats_path, {}},
      {"tiles", o.tiles_csv, {}},
      {"machine-svg", o.pictures.machine_svg, {".svg"}},
      {"ownership", o.pictures.ownership_png, {".png", ".ppm"}},
      {"timeline", o.pictures.timeline_svg, {".svg"}},
      {"report", o.pictures.report_html, {".html", ".htm"}},
      {"replay", o.replay_html, {".html", ".htm"}},
  };
  for (const Named& n : outputs) {
    if (!vm.count(n.option)) continue;
    const std::string option = std::string("--") + n.option;
    if (n.path.empty()) throw UsageError(option + ": needs a file name");
    if (n.extensions.empty()) continue;
    const std::string extension = tracer::lower_extension(n.path);
    if (std::find(n.extensions.begin(), n.extensions.end(), extension) == n.extensions.end()) {
      std::string kinds;
      for (const std::string& e : n.extensions) kinds += (kinds.empty() ? "" : " or ") + e;
      throw UsageError(option + ": expected a " + kinds + " file name, got '" + n.path + "'");
    }
  }
}

}  // namespace

// The sweep describes these too, with its own defaults (the choice's values).
// clang-format off
void add_database_options(po::options_description& d, SharedChoice& c) {
  d.add_options()
      ("accel", po::value(&c.accel)->default_value(c.accel), "acceleration structure: bvh or grid")
      ("bvh-layout", po::value(&c.bvh_layout)->default_value(c.bvh_layout),
       "how BVH nodes fill pages: treelet (each page a piece of the tree a ray goes down, so fewer pages "
       "per pixel) or depth-first (siblings together)")
      ("shadow-rays", po::value(&c.shadow_rays)->default_value(c.shadow_rays),
       "facing: a shadow ray only to lights in front of the surface (SPD); all: one to every "
       "light at every hit, as VM_pRAY counted them (same image, more rays)")
      ("page-size", po::value(&c.page_size)->default_value(c.page_size),
       "database page size in bytes, a power of two from 256 to 65536");
}

void add_farming_options(po::options_description& d, SharedChoice& c) {
  d.add_options()
      ("grain", po::value(&c.grain)->default_value(c.grain),
       "pixels per tile handed out (affinity: the smallest tile), a run of the pixel order")
      ("schedule", po::value(&c.schedule)->default_value(c.schedule),
       "affinity (dynamic, each processor working through its own region first), dynamic (pixels in frame "
       "order to whoever asks, as in the paper), or static (fixed shares)")
      ("pixel-order", po::value(&c.pixel_order)->default_value(c.pixel_order),
       "how pixels are numbered, so where a tile or a share lies: hilbert (along a Hilbert curve: compact "
       "patches whose rays share pages) or scanline (rows, as in the paper)")
      ("prefetch", po::value(&c.prefetch)->default_value(c.prefetch),
       "tiles a pixel computer keeps asked for beyond the one it traces, 0..3 (0: ask when idle, as in the paper)");
}
// clang-format on

DatabaseChoice parse_database(const SharedChoice& c) {
  return {.accel = parse_accel(c.accel),
          .bvh_layout = parse_bvh_layout(c.bvh_layout),
          .shadow_rays_all = parse_shadow_rays(c.shadow_rays),
          .page_size = checked_page_size(c.page_size)};
}

nodes::Farming parse_farming(const SharedChoice& c, const po::variables_map& vm) {
  nodes::Farming f;
  // Their bounds are the machine's (nodes::check_options, called by the parsers).
  f.grain = as_field<std::uint32_t>(c.grain, "--grain");
  f.prefetch = as_field<std::uint16_t>(c.prefetch, "--prefetch");
  f.schedule = parse_schedule(c.schedule);
  f.pixel_order = parse_pixel_order(c.pixel_order);
  check_grain(f.schedule, vm.count("grain") && !vm["grain"].defaulted());
  return f;
}

std::uint32_t checked_page_size(std::int64_t bytes) {
  try {
    tracer::validate_page_size(bytes);
  } catch (const tracer::DatabaseError& e) {
    throw UsageError(std::string("--page-size: ") + e.what());
  }
  return static_cast<std::uint32_t>(bytes);
}

bool parse_shadow_rays(const std::string& policy) {
  if (policy == "facing") return false;
  if (policy == "all") return true;
  throw UsageError("--shadow-rays: expected facing or all, got '" + policy + "'");
}

tracer::Accel parse_accel(const std::string& name) {
  if (name == "bvh") return tracer::Accel::bvh;
  if (name == "grid") return tracer::Accel::grid;
  throw UsageError("--accel: expected bvh or grid, got '" + name + "'");
}

nodes::Schedule parse_schedule(const std::string& name) {
  for (auto schedule : {nodes::Schedule::dynamic, nodes::Schedule::static_split, nodes::Schedule::affinity})
    if (name == nodes::schedule_name(schedule)) return schedule;
  throw UsageError("--schedule: expected dynamic, static or affinity, got '" + name + "'");
}

nodes::PixelOrder parse_pixel_order(const std::string& name) {
  for (auto order : {nodes::PixelOrder::scanline, nodes::PixelOrder::hilbert})
    if (name == nodes::pixel_order_name(order)) return order;
  throw UsageError("--pixel-order: expected scanline or hilbert, got '" + name + "'");
}

std::vector<std::uint8_t> parse_trace_kinds(const std::string& names) {
  std::vector<std::uint8_t> kinds;
  std::string known;
  for (int k = 1; k < nodes::message_kind_count; ++k)
    known += (known.empty() ? "" : ", ") + std::string(nodes::message_kind_name(static_cast<std::uint8_t>(k)));
  std::size_t at = 0;
  do {
    const std::size_t comma = std::min(names.find(',', at), names.size());
    const std::string name = names.substr(at, comma - at);
    int kind = 1;
    while (kind < nodes::message_kind_count && nodes::message_kind_name(static_cast<std::uint8_t>(kind)) != name) ++kind;
    if (kind == nodes::message_kind_count)
      throw UsageError("--trace-kind: expected packet kinds among " + known + ", got '" + name + "'");
    kinds.push_back(static_cast<std::uint8_t>(kind));
    at = comma + 1;
  } while (at <= names.size());
  return kinds;
}

void check_grid_shape(const std::string& kind, std::size_t nodes) {
  if (kind != "mesh" && kind != "torus") return;
  const auto [w, h] = topology::squarest_grid(nodes);
  if (h > 1 || nodes <= 3) return;
  throw UsageError("--topology " + kind + " --nodes " + std::to_string(nodes) + ": the only " + kind + " of " +
                   std::to_string(nodes) + " nodes is " + std::to_string(w) + "x1, a line; give that shape (" +
                   kind + ":" + std::to_string(w) + "x1), a ring, or a count with factors such as " +
                   std::to_string(nodes - 1) + " or " + std::to_string(nodes + 1));
}

void check_grain(nodes::Schedule schedule, bool grain_given) {
  if (schedule == nodes::Schedule::static_split && grain_given)
    throw UsageError("--grain: the static schedule hands out fixed shares, not tiles of a grain");
}

const char* accel_name(tracer::Accel accel) { return accel == tracer::Accel::bvh ? "bvh" : "grid"; }

tracer::BvhLayout parse_bvh_layout(const std::string& name) {
  for (auto layout : {tracer::BvhLayout::treelet, tracer::BvhLayout::depth_first})
    if (name == bvh_layout_name(layout)) return layout;
  throw UsageError("--bvh-layout: expected treelet or depth-first, got '" + name + "'");
}

const char* bvh_layout_name(tracer::BvhLayout layout) {
  return layout == tracer::BvhLayout::treelet ? "treelet" : "depth-first";
}

std::string accel_description(tracer::Accel accel, tracer::BvhLayout layout) {
  if (accel != tracer::Accel::bvh) return accel_name(accel);
  return std::string(accel_name(accel)) + ", " + bvh_layout_name(layout) + " layout";
}

// The build uses the threads the run has (--threads, 0: the usable CPUs); the
// database is the same for any count.
tracer::BuildOptions build_options(const Options& o) {
  return {.accel = o.accel,
          .bvh_layout = o.bvh_layout,
          .page_size = o.page_size,
          .threads = o.machine.threads.count == 0 ? usable_cpus() : o.machine.threads.count};
}

std::string default_output(const std::string& scene) {
  if (scene == "-") return "stdin.png";
  std::string base = scene.substr(scene.find_last_of('/') + 1);
  for (const char* ext : {".gz", ".nff"})
    if (base.size() > std::string(ext).size() && base.ends_with(ext))
      base.resize(base.size() - std::string(ext).size());
  for (char& c : base)
    if (c == ':') c = '-';
  return base + ".png";
}

Options parse_options(int argc, const char* const argv[]) {
  Options o;
  Raw raw;
  // Not in --help: the scene is the positional argument, and the manual page
  // and the completion script are for the build to install.
  po::options_description hidden;
  hidden.add_options()("scene", po::value(&o.scene))("manpage", "print the manual page vmpray(1), roff")(
      "completion", po::value(&o.completion_shell), "print the completion script for this shell (bash)");
  po::options_description all;
  const po::options_description machine = describe_machine(o, raw);
  all.add(describe_render(o, raw)).add(machine).add(hidden);
  po::positional_options_description positional;
  positional.add("scene", 1);
  const po::variables_map vm = read_command_line(argc, argv, all, positional);
  if (vm.count("help")) o.action = Options::Action::help;
  else if (vm.count("version")) o.action = Options::Action::version;
  else if (vm.count("manpage")) o.action = Options::Action::manpage;
  else if (vm.count("completion")) o.action = Options::Action::completion;
  if (vm.count("completion") && o.completion_shell != "bash")
    throw UsageError("--completion: expected bash, got '" + o.completion_shell + "'");
  check_render(o, raw, vm);
  check_output_names(o, vm);
  if (o.single) reject_machine_options(machine, vm);
  raw.timing.profile_given = !vm["profile"].defaulted();
  check_machine(o, raw, vm);
  return o;
}

std::string usage_text() {
  Options o;
  Raw raw;
  std::ostringstream out;
  out << "Usage: vmpray [SCENE] [options]\n"
      << usage_summary() << "\n"
      << describe_render(o, raw) << "\n" << describe_machine(o, raw) << "\nBuilt-in scenes (NAME[:SIZE][:tRES]):\n";
  for (const auto& s : tracer::builtin_scenes()) out << "  " << s.name << "  " << s.description << "\n";
  return out.str();
}

std::string usage_summary() {
  return "Ray traces SCENE (an NFF file, '-' for stdin, or a built-in scene; default teapot)\n"
         "on a simulated distributed-memory machine (default: a 16-node hypercube) whose\n"
         "processors share the scene database as object pages in a virtual memory, and\n"
         "writes an image and a report of rays, page traffic, network and per-node work.\n"
         "The paper's experiments: vmpray sweep nodes|cache [options] (see vmpray sweep --help).\n";
}

// The caption is what --help prints above the options ("Options:"), read
// back from that text since Boost keeps it to itself.
OptionGroup option_group(const po::options_description& d) {
  OptionGroup group;
  std::ostringstream text;
  text << d;
  const std::string first = text.str().substr(0, text.str().find('\n'));
  if (!first.empty() && first.front() != ' ' && first.back() == ':') group.caption = first.substr(0, first.size() - 1);
  for (const auto& option : d.options()) {
    OptionDoc doc;
    doc.name = option->long_name();
    doc.description = option->description();
    const std::string shown = option->canonical_display_name(po::command_line_style::allow_dash_for_short);
    if (shown.size() == 2 && shown[0] == '-') doc.short_name = shown[1];
    doc.takes_value = option->semantic()->max_tokens() > 0;
    doc.takes_text = dynamic_cast<const po::typed_value<std::string>*>(option->semantic().get()) != nullptr;
    // "arg (=hypercube)": the default as --help shows it.
    const std::string parameter = option->format_parameter();
    const std::size_t open = parameter.find(" (=");
    if (doc.takes_value && open != std::string::npos && parameter.back() == ')')
      doc.default_value = parameter.substr(open + 3, parameter.size() - open - 4);
    group.options.push_back(std::move(doc));
  }
  return group;
}

std::vector<OptionGroup> render_option_groups() {
  Options o;
  Raw raw;
  return {option_group(describe_render(o, raw)), option_group(describe_machine(o, raw))};
}

}  // namespace app
