// The manual page and the bash completion script (see manual.hpp). The
// options, their groups, defaults and descriptions, the built-in scenes and
// the words an option's value can be all come from the code that parses
// them; only the prose around them (what vmpray is, the examples, the exit
// statuses) is written here.
#include "app/manual.hpp"

#include <ostream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "app/experiments/network_study.hpp"
#include "app/experiments/sweep.hpp"
#include "app/render/options.hpp"
#include "nodes/machine/pixel_order.hpp"
#include "nodes/machine/work_plan.hpp"
#include "topology/topology.hpp"
#include "tracer/generators.hpp"

namespace app {
namespace {

// ---- The manual page ----

// `text` as roff prints it literally: the characters groff would read as
// escapes or turn into typographic ones are written as escapes, and a dot
// that would open a line (a request) is guarded.
std::string roff(std::string_view text) {
  std::string out;
  for (const char c : text) switch (c) {
      case '\\': out += "\\e"; break;
      case '-': out += "\\-"; break;
      case '\'': out += "\\(aq"; break;
      case '"': out += "\\(dq"; break;
      case '`': out += "\\(ga"; break;
      case '^': out += "\\(ha"; break;
      case '~': out += "\\(ti"; break;
      default: out += c;
    }
  if (!out.empty() && out.front() == '.') out.insert(0, "\\&");
  return out;
}

// Lines of --help prose as text lines (roff fills them into paragraphs).
std::string roff_lines(std::string_view text) {
  std::string out;
  std::istringstream lines{std::string(text)};
  for (std::string line; std::getline(lines, line);) {
    line.erase(0, line.find_first_not_of(' '));  // a leading space would break the line
    if (!line.empty()) out += roff(line) + "\n";
  }
  return out;
}

// "\fB\-o\fR, \fB\-\-output\fR \fIarg\fR", as --help shows "-o [ --output ] arg".
std::string option_heading(const OptionDoc& option) {
  std::string heading;
  if (option.short_name != 0) heading += "\\fB\\-" + roff(std::string(1, option.short_name)) + "\\fR, ";
  heading += "\\fB\\-\\-" + roff(option.name) + "\\fR";
  if (option.takes_value) heading += " \\fIarg\\fR";
  return heading;
}

void write_group(std::ostream& out, const OptionGroup& group) {
  out << ".SS \"" << roff(group.caption) << "\"\n";
  for (const OptionDoc& option : group.options) {
    out << ".TP\n" << option_heading(option) << "\n" << roff(option.description);
    if (!option.default_value.empty()) out << " (default: " << roff(option.default_value) << ")";
    out << "\n";
  }
}

void write_head(std::ostream& out) {
  out << ".TH VMPRAY 1 \"\" \"vmpray " << roff(VMPRAY_VERSION) << "\" \"User Commands\"\n"
      << ".nh\n"  // no hyphenation: option and scene names stay whole
         ".SH NAME\n"
         "vmpray \\- ray trace a scene on a simulated VM_pRAY distributed\\-memory parallel machine\n"
         ".SH SYNOPSIS\n"
         ".B vmpray\n"
         "[\\fISCENE\\fR] [\\fIoptions\\fR]\n"
         ".br\n"
         ".B vmpray sweep\n"
         "\\fBnodes\\fR|\\fBcache\\fR [\\fISCENE\\fR] [\\fIoptions\\fR]\n"
         ".br\n"
         ".B vmpray network\n"
         "[\\fIoptions\\fR]\n"
         ".br\n"
         ".B mpirun\n"
         "[\\fImpirun options\\fR] \\fBvmpray\\fR [\\fISCENE\\fR] [\\fIoptions\\fR]\n"
         ".SH DESCRIPTION\n"
      << roff_lines(usage_summary())
      << ".PP\n"
      << roff_lines("vmpray re-creates VM_pRAY (D. Badouel and T. Priol, An Efficient Parallel Ray Tracing Scheme "
                    "for Highly Parallel Architectures, 1990). Every processor of the machine is a router, a page "
                    "server and pixel computers talking over CSP channels; the scene is packed into object pages, "
                    "page p on node p mod N, read through a shared virtual memory with an LRU cache of remote "
                    "pages. The image is the same for every topology, node count, cache, schedule and thread "
                    "count.")
      << ".PP\n"
      << roff_lines("Started by an MPI launcher with more than one rank, the machine is split over the ranks: "
                    "rank 0 does all a one-process run does, the others run their nodes.");
}

void write_scenes(std::ostream& out) {
  out << ".SH \"BUILT\\-IN SCENES\"\n"
      << roff_lines("A built-in scene is written NAME[:SIZE][:tRES]: a size for the generator, and a resolution "
                    "at which its spheres and cones are tessellated into triangles.");
  for (const tracer::BuiltinScene& scene : tracer::builtin_scenes())
    out << ".TP\n.B " << roff(scene.name) << "\n" << roff(scene.description) << "\n";
}

void write_sweep(std::ostream& out) {
  out << ".SH SWEEP\n"
         ".B vmpray sweep\n"
         "\\fBnodes\\fR|\\fBcache\\fR [\\fISCENE\\fR] [\\fIoptions\\fR]\n"
         ".PP\n"
      << roff_lines(sweep_summary());
  for (const SweepKindDoc& kind : sweep_kinds())
    out << ".TP\n.B " << roff(kind.name) << "\n" << roff(kind.description) << "\n";
  write_group(out, sweep_option_group());
}

void write_network(std::ostream& out) {
  out << ".SH NETWORK\n"
         ".B vmpray network\n"
         "[\\fIoptions\\fR]\n"
         ".PP\n"
      << roff_lines(network_summary());
  std::istringstream patterns(nodes::pattern_descriptions());
  for (std::string line; std::getline(patterns, line);) {
    const std::size_t colon = line.find(':');
    out << ".TP\n.B " << roff(line.substr(0, colon)) << "\n" << roff(line.substr(colon + 2)) << "\n";
  }
  write_group(out, network_option_group());
}

// What the README's tour starts with; tests/app checks each one parses.
struct Example {
  const char* command;
  const char* says;
};
constexpr Example examples[] = {
    {"vmpray", "The teapot on a 16-node hypercube, into teapot.png:"},
    {"vmpray mountain -o mountain.png", "A built-in scene, into a file of its own:"},
    {"vmpray rings4 --cache-pages 256 --stats rings4.json", "A cache of 256 pages per node, and the report as JSON:"},
    {"vmpray teapot --single", "The plain renderer in one process, no machine, on every core:"},
    {"vmpray --topology ring --nodes 8 --trace-routes 5", "The routes of the first five packets, hop by hop:"},
    {"vmpray --topology torus --nodes 64 --machine-svg machine.svg", "The machine, its links drawn by their traffic:"},
    {"vmpray sweep nodes --scene teapot --size 512 --cache-pages 3072 --out table2", "The paper's Table 2:"},
    {"mpirun -np 4 vmpray teapot --topology hypercube:6", "A 64-node machine split over four MPI ranks:"},
};

void write_tail(std::ostream& out) {
  out << ".SH EXAMPLES\n";
  for (const Example& example : examples)
    out << ".PP\n" << roff(example.says) << "\n.RS\n.nf\n\\fB" << roff(example.command) << "\\fR\n.fi\n.RE\n";
  out << ".SH \"EXIT STATUS\"\n"
         ".TP\n.B 0\nSuccess.\n"
         ".TP\n.B 1\n"
      << roff_lines("A run-time error, such as a scene that cannot be read or an output that cannot be written.")
      << ".TP\n.B 2\n"
      << roff_lines("A bad command line, or an image too large for this machine's memory.")
      << ".PP\n"
      << roff_lines("Errors are one line on standard error, and a failed run leaves no output file.")
      << ".SH ENVIRONMENT\n"
         ".TP\n.BR OMPI_COMM_WORLD_SIZE \", \" PMIX_RANK \", \" PMI_RANK \", \" PMI_SIZE \", \" MPI_LOCALNRANKS\n"
      << roff_lines("Set by an MPI launcher: vmpray then runs as one rank of the job.")
      << ".SH \"SEE ALSO\"\n"
         ".BR mpirun (1)\n";
}

// ---- The completion script ----

// The words of a value, for the options whose value is one of a fixed set.
std::vector<std::string> pattern_words() {
  std::vector<std::string> names;
  for (const nodes::TrafficPattern p : nodes::traffic_patterns()) names.emplace_back(nodes::pattern_name(p));
  return names;
}

std::vector<std::pair<std::string, std::vector<std::string>>> value_words() {
  std::vector<std::string> kinds;
  using topology::Kind;
  for (const Kind kind : {Kind::hypercube, Kind::mesh, Kind::torus, Kind::ring, Kind::complete})
    kinds.emplace_back(topology::kind_name(kind));
  std::vector<std::string> schedules;
  for (const auto s : {nodes::Schedule::affinity, nodes::Schedule::dynamic, nodes::Schedule::static_split})
    schedules.emplace_back(nodes::schedule_name(s));
  return {{"topology", kinds},
          {"accel", {accel_name(tracer::Accel::bvh), accel_name(tracer::Accel::grid)}},
          {"bvh-layout",
           {bvh_layout_name(tracer::BvhLayout::treelet), bvh_layout_name(tracer::BvhLayout::depth_first)}},
          {"shadow-rays", {"facing", "all"}},
          {"schedule", schedules},
          {"pixel-order",
           {nodes::pixel_order_name(nodes::PixelOrder::hilbert), nodes::pixel_order_name(nodes::PixelOrder::scanline)}},
          {"distribution", {"modulo", "block"}},
          {"timing", {"real", "virtual"}},
          {"profile", {"ipsc2", "native"}},  // or a profile file
          {"pattern", pattern_words()}};
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& word : words) out += (out.empty() ? "" : " ") + word;
  return out;
}

std::string quoted(const std::string& words) { return std::string(1, '"').append(words).append(1, '"'); }

std::string scene_words() {
  std::vector<std::string> names;
  for (const tracer::BuiltinScene& scene : tracer::builtin_scenes()) names.push_back(scene.name);
  return joined(names);
}

std::string sweep_kind_words() {
  std::vector<std::string> names;
  for (const SweepKindDoc& kind : sweep_kinds()) names.push_back(kind.name);
  return joined(names);
}

std::string option_words(const std::vector<OptionGroup>& groups) {
  std::vector<std::string> words;
  for (const OptionGroup& group : groups)
    for (const OptionDoc& option : group.options) {
      words.push_back("--" + option.name);
      if (option.short_name != 0) words.push_back(std::string("-") + option.short_name);
    }
  return joined(words);
}

// One case of _vmpray's `case "$command:$prev"` for each option of `command`
// that takes a value: its words, the scenes, file names for a text, or
// nothing for a number.
std::string value_cases(const std::string& command, const std::vector<OptionGroup>& groups) {
  const auto words = value_words();
  std::string out;
  for (const OptionGroup& group : groups)
    for (const OptionDoc& option : group.options) {
      if (!option.takes_value) continue;
      std::string pattern = command + ":--" + option.name;
      if (option.short_name != 0) pattern += " | " + command + ":-" + option.short_name;
      // The words, then whether file names are offered too (a profile may be a file).
      std::string offer = option.takes_text ? "\"\" \"$cur\" files" : "\"\" \"$cur\"";
      for (const auto& [name, values] : words)
        if (name == option.name) offer = quoted(joined(values)).append(name == "profile" ? " \"$cur\" files" : " \"$cur\"");
      if (option.name == "scene") offer = "\"$scenes\" \"$cur\" files";
      out.append("    ").append(pattern).append(") _vmpray_offer ").append(offer).append("; return ;;\n");
    }
  return out;
}

}  // namespace

std::string manual_page() {
  std::ostringstream out;
  write_head(out);
  out << ".SH OPTIONS\n";
  for (const OptionGroup& group : render_option_groups()) write_group(out, group);
  write_scenes(out);
  write_sweep(out);
  write_network(out);
  write_tail(out);
  return out.str();
}

std::string bash_completion() {
  const std::vector<OptionGroup> render = render_option_groups(), sweep{sweep_option_group()},
                                 network{network_option_group()};
  std::ostringstream out;
  out << "# bash completion for vmpray(1), made by `vmpray --completion bash` from the\n"
         "# option descriptions --help prints: the options of vmpray, vmpray sweep and vmpray network,\n"
         "# the words of options that take one of a set, the subcommand, the built-in\n"
         "# scenes, and file names otherwise. Needs bash alone.\n\n"
         "# COMPREPLY: the words of $1 that start with $2, and file names too if $3 is given.\n"
         "_vmpray_offer() {\n"
         "  mapfile -t COMPREPLY < <(compgen -W \"$1\" -- \"$2\")\n"
         "  if [[ -n ${3-} ]]; then\n"
         "    compopt -o filenames 2>/dev/null || true\n"
         "    mapfile -t -O \"${#COMPREPLY[@]}\" COMPREPLY < <(compgen -f -- \"$2\")\n"
         "  fi\n"
         "}\n\n"
         "_vmpray() {\n"
         "  local cur=${COMP_WORDS[COMP_CWORD]} prev=\"\" command=render\n"
         "  local scenes=\""
      << scene_words() << "\"\n"
      << "  ((COMP_CWORD > 0)) && prev=${COMP_WORDS[COMP_CWORD - 1]}\n"
         "  [[ ${COMP_WORDS[1]-} == sweep ]] && ((COMP_CWORD > 1)) && command=sweep\n"
         "  [[ ${COMP_WORDS[1]-} == network ]] && ((COMP_CWORD > 1)) && command=network\n"
         "  case \"$command:$prev\" in\n"
      << value_cases("render", render) << value_cases("sweep", sweep) << value_cases("network", network)
      << "  esac\n"
         "  if [[ $cur == -* ]]; then\n"
         "    if [[ $command == sweep ]]; then _vmpray_offer \""
      << option_words(sweep) << "\" \"$cur\"\n    elif [[ $command == network ]]; then _vmpray_offer \""
      << option_words(network) << "\" \"$cur\"\n    else _vmpray_offer \"" << option_words(render)
      << "\" \"$cur\"; fi\n"
         "  elif [[ $command == sweep ]] && ((COMP_CWORD == 2)); then\n"
         "    _vmpray_offer \""
      << sweep_kind_words() << "\" \"$cur\"\n"
         "  elif ((COMP_CWORD == 1)); then\n"
         "    _vmpray_offer \"sweep network $scenes\" \"$cur\" files\n"
         "  else\n"
         "    _vmpray_offer \"$scenes\" \"$cur\" files\n"
         "  fi\n"
         "}\n\n"
         "complete -F _vmpray vmpray\n";
  return out.str();
}

}  // namespace app
