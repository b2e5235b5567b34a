// Topology specification parser: "KIND[:SIZE]" plus an optional node count.
#include "topology/spec.hpp"

#include <bit>
#include <charconv>
#include <stdexcept>
#include <string>

namespace topology {
namespace {

[[noreturn]] void fail(std::string_view spec, const std::string& why) {
  throw std::invalid_argument("topology '" + std::string(spec) + "': " + why);
}

// Appending (rather than "'" + text) sidesteps a false -Wrestrict in GCC 12.
std::string quoted(std::string_view text) {
  std::string s = "'";
  s.append(text).append("'");
  return s;
}

std::optional<Kind> kind_from(std::string_view name) {
  for (Kind k : {Kind::hypercube, Kind::mesh, Kind::torus, Kind::ring, Kind::complete})
    if (name == kind_name(k)) return k;
  return std::nullopt;
}

// A decimal count, bounded so that a product of two never overflows.
unsigned parse_count(std::string_view spec, std::string_view text) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    fail(spec, quoted(text) + " is not a number");
  if (value > max_nodes)
    fail(spec, std::to_string(value) + " is larger than the maximum of " +
                   std::to_string(max_nodes) + " nodes");
  return value;
}

std::pair<unsigned, unsigned> parse_grid(std::string_view spec, std::string_view text) {
  const auto x = text.find('x');
  if (x == std::string_view::npos) fail(spec, "expected WIDTHxHEIGHT, e.g. 8x8");
  return {parse_count(spec, text.substr(0, x)), parse_count(spec, text.substr(x + 1))};
}

// The number of nodes a bare kind gets from the count given, or from its own size.
std::size_t checked_nodes(std::string_view spec, std::optional<std::size_t> nodes) {
  if (!nodes) fail(spec, "give a size (e.g. mesh:8x8) or a node count");
  if (*nodes == 0) fail(spec, "needs at least one node");
  if (*nodes > max_nodes)
    fail(spec, std::to_string(*nodes) + " nodes is more than the maximum of " +
                   std::to_string(max_nodes));
  return *nodes;
}

Topology from_count(std::string_view spec, Kind kind, std::size_t n) {
  const auto count = static_cast<unsigned>(n);
  switch (kind) {
    case Kind::hypercube:
      if (!std::has_single_bit(count))
        fail(spec, "a hypercube needs a power of two nodes, not " + std::to_string(n));
      return Topology::hypercube(static_cast<unsigned>(std::countr_zero(count)));
    case Kind::mesh:
    case Kind::torus: {
      const auto [w, h] = squarest_grid(n);
      return kind == Kind::mesh ? Topology::mesh(w, h) : Topology::torus(w, h);
    }
    case Kind::ring: return Topology::ring(count);
    case Kind::complete: return Topology::complete(count);
  }
  fail(spec, "unknown kind");
}

Topology from_size(std::string_view spec, Kind kind, std::string_view size) {
  switch (kind) {
    case Kind::hypercube: {
      const unsigned d = parse_count(spec, size);
      if (d > 12) fail(spec, "dimension " + std::to_string(d) + " is more than 4096 nodes");
      return Topology::hypercube(d);
    }
    case Kind::mesh:
    case Kind::torus: {
      const auto [w, h] = parse_grid(spec, size);
      if (w == 0 || h == 0) fail(spec, "needs at least one node");
      if (std::size_t{w} * h > max_nodes)
        fail(spec, std::to_string(std::size_t{w} * h) + " nodes is more than the maximum of " +
                       std::to_string(max_nodes));
      return kind == Kind::mesh ? Topology::mesh(w, h) : Topology::torus(w, h);
    }
    default: {
      const unsigned n = parse_count(spec, size);
      if (n == 0) fail(spec, "needs at least one node");
      return kind == Kind::ring ? Topology::ring(n) : Topology::complete(n);
    }
  }
}

}  // namespace

std::pair<unsigned, unsigned> squarest_grid(std::size_t nodes) {
  unsigned h = 1;
  for (unsigned d = 1; std::size_t{d} * d <= nodes; ++d)
    if (nodes % d == 0) h = d;
  return {static_cast<unsigned>(nodes / h), h};
}

Topology parse_topology(std::string_view spec, std::optional<std::size_t> nodes) {
  const auto colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const auto kind = kind_from(name);
  if (!kind)
    fail(spec, "unknown kind " + quoted(name) +
                   " (expected hypercube, mesh, torus, ring or complete)");
  if (colon == std::string_view::npos) return from_count(spec, *kind, checked_nodes(spec, nodes));
  Topology t = from_size(spec, *kind, spec.substr(colon + 1));
  if (nodes && *nodes != t.size())
    fail(spec, "has " + std::to_string(t.size()) + " nodes, but the node count asked for is " + std::to_string(*nodes));
  return t;
}

}  // namespace topology
