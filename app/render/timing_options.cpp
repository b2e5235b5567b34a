// --timing, --profile, --cost and the picture options (see timing_options.hpp).
#include "app/render/timing_options.hpp"

#include <stdexcept>

#include "app/render/usage_error.hpp"

namespace app {

namespace po = boost::program_options;

// One option a line, as Boost's examples lay them out.
// clang-format off
void add_model_options(po::options_description& d, TimingChoice& timing) {
  d.add_options()
      ("profile", po::value(&timing.profile)->default_value("ipsc2"),
       "machine model for virtual time: ipsc2, native (calibrated here), or a 'key = value' file")
      ("cost", po::value(&timing.costs),
       "costs over the profile: box=,prim=,shade=,page=,serve=,msg=,hop= (s, ms, us, ns), bw= (B/s, KB/s, MB/s; 0: unlimited)");
}

void add_timing_options(po::options_description& d, TimingChoice& timing, PicturePaths& pictures) {
  d.add_options()
      ("timing", po::value(&timing.timing)->default_value("real"),
       "real (wall time) or virtual: the time a real machine would take under --profile "
       "(deterministic; the machine runs on one thread)");
  add_model_options(d, timing);
  d.add_options()
      ("machine-svg", po::value(&pictures.machine_svg), "after a machine render: the machine with its traffic, SVG")
      ("ownership", po::value(&pictures.ownership_png), "after a machine render: which node computed each pixel, PNG")
      ("timeline", po::value(&pictures.timeline_svg),
       "after a machine render: when each processor traced each tile, coloured by its page requests, SVG")
      ("report", po::value(&pictures.report_html),
       "after a machine render: one self-contained HTML page with the image, statistics and pictures");
}
// clang-format on

nodes::CostModel cost_model_from(const std::string& profile, const std::string& costs) {
  nodes::CostModel model;
  try {
    model = profile == "ipsc2" || profile == "native" ? nodes::profile_named(profile)
                                                      : nodes::read_profile_file(profile);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--profile: ") + e.what());
  }
  try {
    if (!costs.empty()) nodes::apply_costs(model, costs, "--cost");
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return model;
}

std::optional<nodes::CostModel> timing_from(const TimingChoice& choice) {
  if (choice.timing == "real") {
    for (const auto& [option, given] : {std::pair{"--profile", choice.profile_given}, {"--cost", !choice.costs.empty()}})
      if (given) throw UsageError(std::string(option) + ": a model for --timing virtual, but this run is timed for real");
    return std::nullopt;
  }
  if (choice.timing != "virtual")
    throw UsageError("--timing: expected real or virtual, got '" + choice.timing + "'");
  return cost_model_from(choice.profile, choice.costs);
}

}  // namespace app
