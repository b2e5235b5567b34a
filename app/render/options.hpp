// Command-line options of `vmpray`: one struct and its parser. The parser only
// checks values; it opens no files (scene and output are checked by the caller).
// Invariant: a parsed Options has a topology that fits its node count and a
// cache of at least one page (as far as that can be told without the scene).
#pragma once

#include <boost/program_options/options_description.hpp>
#include <boost/program_options/variables_map.hpp>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/render/timing_options.hpp"
#include "app/render/usage_error.hpp"
#include "nodes/machine/machine.hpp"
#include "nodes/machine/pixel_order.hpp"
#include "nodes/machine/work_plan.hpp"
#include "tracer/database.hpp"

namespace app {

struct Options {
  // help, version, manpage and completion print their text (--help, --version,
  // and the hidden --manpage and --completion SHELL) and render nothing.
  enum class Action { render, help, version, manpage, completion };
  Action action = Action::render;
  std::string completion_shell;   // --completion: "bash", the only one
  std::string scene = "teapot";   // NFF path, "-" for stdin, or a built-in spec
  std::string output;             // .png or .ppm; derived from the scene when empty
  std::string stats_path;         // JSON report, none when empty
  bool spd_procedure = false;
  bool shadow_rays_all = false;  // --shadow-rays all: one per light at every hit
  tracer::Accel accel = tracer::Accel::bvh;
  tracer::BvhLayout bvh_layout = tracer::BvhLayout::treelet;
  std::uint32_t page_size = tracer::BuildOptions{}.page_size;
  int max_depth = 5;
  int width = 0;       // 0: the scene's resolution
  int height = 0;
  int tessellate = 0;  // 0: keep spheres and cones as they are
  bool quiet = false;
  bool estimate_memory = false;  // print the memory the run needs and render nothing
  // The distributed machine (the default) or the plain in-process renderer.
  bool single = false;
  bool compare_serial = false;  // also run the 1-node machine: speedup, efficiency
  // Topology, nodes, threads, cache, grain, schedule, pixel order, workers,
  // distribution and route tracing; trace and progress are filled in at run time.
  nodes::MachineOptions machine;
  PicturePaths pictures;  // written after a machine render (timing_options.hpp)
  std::string tiles_csv;  // the machine's tile timeline (machine_summary.hpp), none when empty
  std::string replay_html;  // the replay page of the run (app/experiments/replay.hpp), none when empty
};

// ---- Options a render and a sweep share ----
// Both commands describe them with add_database_options and
// add_farming_options and parse them with parse_database and parse_farming;
// each starts from its own defaults (these are the render's: the
// database's and the machine's own).
struct SharedChoice {
  std::string accel = "bvh", bvh_layout = "treelet", shadow_rays = "facing";
  std::int64_t page_size = tracer::BuildOptions{}.page_size;
  std::int64_t grain = nodes::Farming{}.grain, prefetch = nodes::Farming{}.prefetch;
  std::string schedule = nodes::schedule_name(nodes::Farming{}.schedule),
              pixel_order = nodes::pixel_order_name(nodes::Farming{}.pixel_order);
};

// How the database is built and traced: --accel, --bvh-layout, --shadow-rays, --page-size.
struct DatabaseChoice {
  tracer::Accel accel = tracer::Accel::bvh;
  tracer::BvhLayout bvh_layout = tracer::BvhLayout::treelet;
  bool shadow_rays_all = false;
  std::uint32_t page_size = tracer::BuildOptions{}.page_size;
};
void add_database_options(boost::program_options::options_description& d, SharedChoice& choice);
DatabaseChoice parse_database(const SharedChoice& choice);

// How the pixels are handed out: --grain, --schedule, --pixel-order, --prefetch.
void add_farming_options(boost::program_options::options_description& d, SharedChoice& choice);
// Also refuses a --grain given with the static schedule (check_grain).
nodes::Farming parse_farming(const SharedChoice& choice, const boost::program_options::variables_map& vm);

// v as a T when lo <= v <= hi; else UsageError "OPTION: expected lo..hi, got v".
template <class T>
T in_range(std::int64_t v, std::int64_t lo, std::int64_t hi, const char* option) {
  if (v < lo || v > hi)
    throw UsageError(std::string(option) + ": expected " + std::to_string(lo) + ".." + std::to_string(hi) +
                     ", got " + std::to_string(v));
  return static_cast<T>(v);
}

// v as a T when a T can hold it, for a field whose bounds the library below
// checks (nodes::check_options); else UsageError "OPTION: must not be
// negative, got v" (or "is too large").
template <class T>
T as_field(std::int64_t v, const char* option) {
  if (v < static_cast<std::int64_t>(std::numeric_limits<T>::min()))
    throw UsageError(std::string(option) + ": must not be negative, got " + std::to_string(v));
  if (static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
    throw UsageError(std::string(option) + ": is too large, got " + std::to_string(v));
  return static_cast<T>(v);
}

// --page-size: bytes if the database takes pages of that size (a power of
// two in its range); UsageError naming the option otherwise.
std::uint32_t checked_page_size(std::int64_t bytes);

// Throws UsageError. argv[0] is the program name.
Options parse_options(int argc, const char* const argv[]);

// --shadow-rays: "facing" -> false, "all" -> true; UsageError otherwise.
bool parse_shadow_rays(const std::string& policy);
// --accel: "bvh" or "grid"; UsageError otherwise. accel_name() is the inverse.
tracer::Accel parse_accel(const std::string& name);
const char* accel_name(tracer::Accel accel);
// --bvh-layout: "treelet" or "depth-first"; UsageError otherwise. bvh_layout_name() is the inverse.
tracer::BvhLayout parse_bvh_layout(const std::string& name);
const char* bvh_layout_name(tracer::BvhLayout layout);
// "bvh, treelet layout", "bvh, depth-first layout" or "grid", for reports.
std::string accel_description(tracer::Accel accel, tracer::BvhLayout layout);
// The database build the options ask for.
tracer::BuildOptions build_options(const Options& o);
// --schedule: "dynamic", "static" or "affinity"; UsageError otherwise.
nodes::Schedule parse_schedule(const std::string& name);
// --pixel-order: "scanline" or "hilbert"; UsageError otherwise.
nodes::PixelOrder parse_pixel_order(const std::string& name);
// --trace-kind: packet kinds by name, comma-separated ("page_request,page_reply");
// UsageError naming the option and the kinds there are otherwise.
std::vector<std::uint8_t> parse_trace_kinds(const std::string& names);
// A bare mesh or torus whose node count has no factors would be a line
// (mesh --nodes 17 is 17x1): UsageError asking for the shape or another
// count, since a line is not what "mesh" promises. Other kinds, full specs
// and counts up to 3 (whose only grids are lines) pass.
void check_grid_shape(const std::string& kind, std::size_t nodes);
// --grain given (grain_given) with the static schedule: UsageError, since
// that schedule hands out fixed shares and the grain would change nothing.
void check_grain(nodes::Schedule schedule, bool grain_given);

// The --help text (options and built-in scenes).
std::string usage_text();
// What a render does, the lines under --help's usage line.
std::string usage_summary();

// ---- The options as documentation ----
// One option as --help lists it: the manual page and the shell completion
// (app/manual.hpp) are made from these, so they name what the parser takes.
struct OptionDoc {
  std::string name;            // the long name, without "--"
  char short_name = 0;         // 'o' for -o; 0 when there is none
  bool takes_value = false;
  bool takes_text = false;     // the value is text (a file, a spec, a list), not a number
  std::string default_value;   // as --help shows it; empty when none
  std::string description;
};
struct OptionGroup {
  std::string caption;  // the heading --help prints above them
  std::vector<OptionDoc> options;
};
OptionGroup option_group(const boost::program_options::options_description& d);
// The render's options, in --help's groups and order.
std::vector<OptionGroup> render_option_groups();

// "teapot" -> "teapot.png", "tetra:9" -> "tetra-9.png", "dir/x.nff.gz" -> "x.png".
std::string default_output(const std::string& scene);

}  // namespace app
