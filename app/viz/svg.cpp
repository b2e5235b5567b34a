// XML escaping and inlinable SVG documents; see svg.hpp for the invariants.
#include "app/viz/svg.hpp"

#include <array>
#include <atomic>
#include <cstdint>

namespace viz {
namespace {

std::atomic<std::uint64_t> documents{0};

}  // namespace

std::string escape_xml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string inlinable_svg(std::string_view svg) {
  if (svg.substr(0, 5) == "<?xml") {
    const std::size_t end = svg.find("?>");
    svg.remove_prefix(end == std::string_view::npos ? svg.size() : end + 2);
  }
  while (!svg.empty() && (svg.front() == '\n' || svg.front() == '\r' || svg.front() == ' ')) svg.remove_prefix(1);
  const std::string prefix = "viz" + std::to_string(++documents) + "-";
  // Where an id is defined or referred to: the prefix goes right after each.
  static constexpr std::array<std::string_view, 3> openings{" id=\"", "href=\"#", "url(#"};
  std::array<std::size_t, openings.size()> next{};  // where each opening occurs next
  for (std::size_t k = 0; k < openings.size(); ++k) next[k] = svg.find(openings[k]);
  std::string out;
  out.reserve(svg.size() + svg.size() / 16);
  std::size_t i = 0;
  for (;;) {
    std::size_t k = 0;
    for (std::size_t j = 1; j < openings.size(); ++j)
      if (next[j] < next[k]) k = j;
    if (next[k] == std::string_view::npos) break;
    const std::size_t end = next[k] + openings[k].size();
    out.append(svg.substr(i, end - i));
    out += prefix;
    i = end;
    next[k] = svg.find(openings[k], i);
  }
  out.append(svg.substr(i));
  return out;
}

}  // namespace viz
