// The machine's option errors named by their options; see usage_error.hpp.
#include "app/render/usage_error.hpp"

#include <utility>

namespace app {

std::string option_of_field(const std::string& field) {
  // clang-format off
  static const std::pair<const char*, const char*> options[] = {
      {"topology", "--topology"}, {"nodes", "--nodes"}, {"threads", "--threads"},
      {"cache_pages", "--cache-pages"}, {"cache_kb", "--cache-kb"}, {"grain", "--grain"},
      {"schedule", "--schedule"}, {"pixel_order", "--pixel-order"}, {"workers_per_node", "--workers-per-node"},
      {"prefetch", "--prefetch"}, {"distribution", "--distribution"}, {"trace_routes", "--trace-routes"},
      {"trace_kinds", "--trace-kind"}, {"timing", "--timing"},
  };
  // clang-format on
  for (const auto& [name, option] : options)
    if (field == name) return option;
  return field;
}

UsageError usage_error(const nodes::OptionError& error) {
  return UsageError(option_of_field(error.field()) + ": " + error.reason());
}

namespace po = boost::program_options;

po::variables_map read_command_line(int argc, const char* const argv[], const po::options_description& options,
                                    const po::positional_options_description& positional) {
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(argc, argv).options(options).positional(positional).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw UsageError(e.what());
  }
  return vm;
}

}  // namespace app
