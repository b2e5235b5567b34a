// Option parsing with Boost.Program_options; every failure becomes a one-line
// UsageError naming the option.
#include "app/options.hpp"

#include <algorithm>
#include <boost/program_options.hpp>
#include <sstream>

#include "tracer/generators.hpp"

namespace app {
namespace po = boost::program_options;
namespace {

po::options_description describe(Options& o, std::string& accel, std::int64_t& page_size) {
  po::options_description d("Options");
  d.add_options()
      ("help,h", "show this help and exit")
      ("version", "show the version and exit")
      ("output,o", po::value(&o.output), "output image, .png or .ppm (default: SCENE.png)")
      ("stats", po::value(&o.stats_path), "write the report as JSON to this file")
      ("spd-procedure", po::bool_switch(&o.spd_procedure),
       "SPD testing procedure: pixel-corner eye rays, depth 5, no adaptive cut-off")
      ("accel", po::value(&accel)->default_value("bvh"), "acceleration structure: bvh or grid")
      ("page-size", po::value(&page_size)->default_value(1024),
       "database page size in bytes, a power of two from 256 to 65536")
      ("max-depth", po::value(&o.max_depth)->default_value(5), "maximum ray depth (eye ray = 1)")
      ("width", po::value(&o.width), "image width (default: the scene's)")
      ("height", po::value(&o.height), "image height (default: the scene's)")
      ("tessellate", po::value(&o.tessellate),
       "tessellate spheres and cones into triangles at this resolution")
      ("quiet,q", po::bool_switch(&o.quiet), "no progress bar and no report");
  return d;
}

void check_values(Options& o, const std::string& accel, std::int64_t page_size) {
  if (accel == "bvh") o.accel = tracer::Accel::bvh;
  else if (accel == "grid") o.accel = tracer::Accel::grid;
  else throw UsageError("--accel: expected bvh or grid, got '" + accel + "'");
  try {
    tracer::validate_page_size(static_cast<std::uint64_t>(std::max<std::int64_t>(page_size, 0)));
  } catch (const tracer::DatabaseError& e) {
    throw UsageError(std::string("--page-size: ") + e.what());
  }
  o.page_size = static_cast<std::uint32_t>(page_size);
  if (o.max_depth < 1 || o.max_depth > 64) throw UsageError("--max-depth: expected 1..64");
  if (o.width < 0 || o.width > 16384) throw UsageError("--width: expected 1..16384");
  if (o.height < 0 || o.height > 16384) throw UsageError("--height: expected 1..16384");
  if (o.tessellate < 0 || o.tessellate > 256) throw UsageError("--tessellate: expected 1..256");
  if (o.output.empty()) o.output = default_output(o.scene);
}

}  // namespace

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
  std::string accel;
  std::int64_t page_size = 0;
  auto desc = describe(o, accel, page_size);
  po::options_description hidden;
  hidden.add_options()("scene", po::value(&o.scene));
  po::options_description all;
  all.add(desc).add(hidden);
  po::positional_options_description positional;
  positional.add("scene", 1);
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(argc, argv).options(all).positional(positional).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw UsageError(e.what());
  }
  if (vm.count("help")) o.action = Options::Action::help;
  else if (vm.count("version")) o.action = Options::Action::version;
  check_values(o, accel, page_size);
  return o;
}

std::string usage_text() {
  Options o;
  std::string accel;
  std::int64_t page_size = 0;
  std::ostringstream out;
  out << "Usage: vmpray [SCENE] [options]\n"
         "Ray traces SCENE (an NFF file, '-' for stdin, or a built-in scene; default teapot)\n"
         "and writes an image and a report of rays, intersection tests and database pages.\n\n"
      << describe(o, accel, page_size) << "\nBuilt-in scenes (NAME[:SIZE][:tRES]):\n";
  for (const auto& s : tracer::builtin_scenes()) out << "  " << s.name << "  " << s.description << "\n";
  return out.str();
}

}  // namespace app
