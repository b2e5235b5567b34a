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

}  // namespace app
