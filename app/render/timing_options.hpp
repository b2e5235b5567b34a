// The command-line face of virtual time and of the pictures of a machine run:
// --timing real|virtual, --profile NAME|FILE, --cost key=value,...,
// --machine-svg, --ownership, --timeline, --report. Kept apart from options.cpp so the
// sweep subcommand describes and parses machine models the same way.
#pragma once

#include <optional>
#include <string>

#include <boost/program_options/options_description.hpp>

#include "nodes/machine/timing.hpp"

namespace app {

struct TimingChoice {
  std::string timing = "real";     // real | virtual
  std::string profile = "ipsc2";   // ipsc2 | native | a profile file
  std::string costs;               // --cost items over the profile
  bool profile_given = false;      // --profile was on the command line
};

struct PicturePaths {
  std::string machine_svg;    // the machine with its traffic, after a machine render
  std::string ownership_png;  // which processor computed each pixel
  std::string report_html;    // image, statistics, machine picture, ownership and timeline together
  std::string timeline_svg;   // when each processor traced each tile
};

// --timing, --profile, --cost and the pictures, for a render.
void add_timing_options(boost::program_options::options_description& d, TimingChoice& timing,
                        PicturePaths& pictures);
// --profile and --cost alone, for the sweep (always in virtual time).
void add_model_options(boost::program_options::options_description& d, TimingChoice& timing);

// The model of --profile and --cost; UsageError naming the option (or
// FILE:LINE for a profile file) when either is bad.
nodes::CostModel cost_model_from(const std::string& profile, const std::string& costs);

// The machine's timing: none for --timing real, the model for virtual.
// A --profile or --cost with real timing is a UsageError: it would change
// nothing.
std::optional<nodes::CostModel> timing_from(const TimingChoice& choice);

}  // namespace app
