// Small pieces of the wording of reports and messages, so that every one
// says a count and a size the same way: "1 node", "16 nodes"; "768.0 KB",
// "953.7 GB" (binary units, as the KB of page sizes are).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace app {

// "1 node", "2 nodes"; `plural` when adding an s will not do.
inline std::string count_of(std::uint64_t n, const std::string& singular, const std::string& plural = "") {
  return std::to_string(n) + " " + (n == 1 ? singular : plural.empty() ? singular + "s" : plural);
}

// bytes in the largest binary unit (KB, MB, GB, TB) that leaves at least 1, one decimal.
inline std::string size_text(double bytes) {
  const char* units[] = {"KB", "MB", "GB", "TB"};
  double value = bytes / 1024.0;
  int unit = 0;
  while (value >= 1024.0 && unit < 3) value /= 1024.0, ++unit;
  char text[48];
  std::snprintf(text, sizeof text, "%.1f %s", value, units[unit]);
  return text;
}

}  // namespace app
