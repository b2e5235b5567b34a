// Topology: neighbours, ports, closed-form distances and the routing
// functions (e-cube, dimension order, shortest way round, direct).
#include "topology/topology.hpp"

#include <bit>
#include <stdexcept>

namespace topology {
namespace {

void check_size(std::size_t nodes, const char* what) {
  if (nodes == 0) throw std::invalid_argument(std::string(what) + " needs at least one node");
  if (nodes > max_nodes)
    throw std::invalid_argument(std::string(what) + " of " + std::to_string(nodes) +
                                " nodes is larger than the maximum of " +
                                std::to_string(max_nodes));
}

// Sum of |i - j| over ordered pairs of a line of n positions: n(n^2-1)/3.
std::uint64_t line_total(std::uint64_t n) { return n * (n * n - 1) / 3; }

// Sum of ring distances over ordered pairs of a ring of n: n * floor(n^2/4).
std::uint64_t ring_total(std::uint64_t n) { return n * (n * n / 4); }

}  // namespace

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::hypercube: return "hypercube";
    case Kind::mesh: return "mesh";
    case Kind::torus: return "torus";
    case Kind::ring: return "ring";
    case Kind::complete: return "complete";
  }
  return "?";
}

int ring_direction(unsigned a, unsigned b, unsigned extent) {
  if (a == b) return 0;
  const unsigned forward = (b + extent - a) % extent;
  return forward <= extent - forward ? +1 : -1;
}

unsigned ring_distance(unsigned a, unsigned b, unsigned extent) {
  const unsigned forward = (b + extent - a) % extent;
  return std::min(forward, extent - forward);
}

Topology::Topology(Kind kind, unsigned width, unsigned height, unsigned dimension)
    : kind_(kind), width_(width), height_(height), dimension_(dimension) {}

Topology Topology::hypercube(unsigned dimension) {
  if (dimension > 12)
    throw std::invalid_argument("hypercube of dimension " + std::to_string(dimension) +
                                " is larger than the maximum of " + std::to_string(max_nodes) +
                                " nodes");
  return Topology(Kind::hypercube, 1u << dimension, 1, dimension);
}

Topology Topology::mesh(unsigned width, unsigned height) {
  check_size(static_cast<std::size_t>(width) * height, "mesh");
  return Topology(Kind::mesh, width, height, 0);
}

Topology Topology::torus(unsigned width, unsigned height) {
  check_size(static_cast<std::size_t>(width) * height, "torus");
  return Topology(Kind::torus, width, height, 0);
}

Topology Topology::ring(unsigned nodes) {
  check_size(nodes, "ring");
  return Topology(Kind::ring, nodes, 1, 0);
}

Topology Topology::complete(unsigned nodes) {
  check_size(nodes, "complete graph");
  return Topology(Kind::complete, nodes, 1, 0);
}

std::string Topology::spec() const {
  std::string s = std::string(kind_name(kind_)) + ":";
  switch (kind_) {
    case Kind::hypercube: return s + std::to_string(dimension_);
    case Kind::mesh:
    case Kind::torus: return s + std::to_string(width_) + "x" + std::to_string(height_);
    default: return s + std::to_string(width_);
  }
}

std::vector<NodeId> Topology::grid_neighbours(NodeId n) const {
  const unsigned x = n % width_, y = n / width_;
  const bool wrap = kind_ == Kind::torus;
  std::vector<NodeId> out;
  auto add = [&](bool exists, unsigned nx, unsigned ny) {
    const NodeId m = ny * width_ + nx;
    if (!exists || m == n) return;
    for (NodeId seen : out)
      if (seen == m) return;
    out.push_back(m);
  };
  add(wrap || x + 1 < width_, (x + 1) % width_, y);
  add(wrap || x > 0, (x + width_ - 1) % width_, y);
  add(wrap || y + 1 < height_, x, (y + 1) % height_);
  add(wrap || y > 0, x, (y + height_ - 1) % height_);
  return out;
}

unsigned Topology::degree(NodeId n) const {
  switch (kind_) {
    case Kind::hypercube: return dimension_;
    case Kind::complete: return width_ - 1;
    case Kind::ring: return width_ >= 3 ? 2 : width_ - 1;
    default: return static_cast<unsigned>(grid_neighbours(n).size());
  }
}

NodeId Topology::neighbour(NodeId n, Port p) const {
  switch (kind_) {
    case Kind::hypercube: return n ^ (1u << p);
    case Kind::complete: return p < n ? p : p + 1;
    case Kind::ring: return p == 0 ? (n + 1) % width_ : (n + width_ - 1) % width_;
    default: return grid_neighbours(n).at(p);
  }
}

std::vector<NodeId> Topology::neighbours(NodeId n) const {
  if (kind_ == Kind::mesh || kind_ == Kind::torus) return grid_neighbours(n);
  std::vector<NodeId> out;
  for (Port p = 0; p < degree(n); ++p) out.push_back(neighbour(n, p));
  return out;
}

Port Topology::port_to(NodeId n, NodeId m) const {
  switch (kind_) {
    case Kind::hypercube: return static_cast<Port>(std::countr_zero(n ^ m));
    case Kind::complete: return m < n ? m : m - 1;
    case Kind::ring: return m == (n + 1) % width_ ? 0 : 1;
    default: {
      const auto nbs = grid_neighbours(n);
      for (Port p = 0; p < nbs.size(); ++p)
        if (nbs[p] == m) return p;
      throw std::logic_error("port_to: " + std::to_string(m) + " is not a neighbour of " +
                             std::to_string(n));
    }
  }
}

std::vector<unsigned> Topology::coordinates(NodeId n) const {
  if (kind_ == Kind::mesh || kind_ == Kind::torus) return {n % width_, n / width_};
  if (kind_ != Kind::hypercube) return {n};
  std::vector<unsigned> bits;
  for (unsigned i = 0; i < dimension_; ++i) bits.push_back((n >> i) & 1u);
  return bits;
}

unsigned Topology::distance(NodeId a, NodeId b) const {
  const unsigned ax = a % width_, ay = a / width_, bx = b % width_, by = b / width_;
  switch (kind_) {
    case Kind::hypercube: return static_cast<unsigned>(std::popcount(a ^ b));
    case Kind::complete: return a == b ? 0 : 1;
    case Kind::ring: return ring_distance(a, b, width_);
    case Kind::mesh: return (ax > bx ? ax - bx : bx - ax) + (ay > by ? ay - by : by - ay);
    case Kind::torus: return ring_distance(ax, bx, width_) + ring_distance(ay, by, height_);
  }
  return 0;
}

unsigned Topology::diameter() const {
  switch (kind_) {
    case Kind::hypercube: return dimension_;
    case Kind::complete: return size() > 1 ? 1 : 0;
    case Kind::ring: return width_ / 2;
    case Kind::mesh: return (width_ - 1) + (height_ - 1);
    case Kind::torus: return width_ / 2 + height_ / 2;
  }
  return 0;
}

std::uint64_t Topology::total_distance() const {
  const std::uint64_t n = size(), w = width_, h = height_;
  switch (kind_) {
    case Kind::hypercube: return dimension_ == 0 ? 0 : n * dimension_ * (n / 2);
    case Kind::complete: return n * (n - 1);
    case Kind::ring: return ring_total(n);
    case Kind::mesh: return h * h * line_total(w) + w * w * line_total(h);
    case Kind::torus: return h * h * ring_total(w) + w * w * ring_total(h);
  }
  return 0;
}

double Topology::average_distance() const {
  const std::uint64_t n = size();
  if (n < 2) return 0.0;
  return static_cast<double>(total_distance()) / static_cast<double>(n * (n - 1));
}

unsigned Topology::buffer_classes() const {
  return kind_ == Kind::ring || kind_ == Kind::torus ? 2 : 1;
}

Hop Topology::naive_next_hop(NodeId from, NodeId to) const {
  Hop hop = next_hop(from, to);
  hop.buffer_class = 0;
  return hop;
}

// A wrapped dimension is cut by a dateline at its wrap link. A packet whose
// remaining path in this dimension still crosses the wrap link travels in
// class 0; once nothing wraps ahead it travels in class 1. Class-0 channels
// never depend on the class-0 channel after the wrap (the packet has turned
// into class 1 there) and class 1 never uses the wrap link, so neither class
// closes a cycle; and a packet never goes from class 1 back to class 0.
static std::uint8_t dateline_class(unsigned at, unsigned target, int direction) {
  const bool wraps_ahead = direction > 0 ? target < at : target > at;
  return wraps_ahead ? 0 : 1;
}

Hop Topology::grid_hop(NodeId from, NodeId to) const {
  const unsigned x = from % width_, y = from / width_, tx = to % width_, ty = to / width_;
  const bool wrap = kind_ == Kind::torus;
  // Dimension order: correct x completely, then y.
  const bool in_x = x != tx;
  const unsigned at = in_x ? x : y, target = in_x ? tx : ty, extent = in_x ? width_ : height_;
  const int dir = wrap ? ring_direction(at, target, extent) : (target > at ? +1 : -1);
  const unsigned next = (at + extent + static_cast<unsigned>(dir)) % extent;
  const NodeId m = in_x ? y * width_ + next : next * width_ + x;
  return Hop{port_to(from, m), wrap ? dateline_class(at, target, dir) : std::uint8_t{0}};
}

Hop Topology::next_hop(NodeId from, NodeId to) const {
  if (from == to) throw std::logic_error("next_hop: packet is already at its destination");
  switch (kind_) {
    case Kind::hypercube:
      // E-cube: correct the lowest differing address bit first.
      return Hop{static_cast<Port>(std::countr_zero(from ^ to)), 0};
    case Kind::complete: return Hop{port_to(from, to), 0};
    case Kind::ring: {
      const int dir = ring_direction(from, to, width_);
      const NodeId m = (from + width_ + static_cast<unsigned>(dir)) % width_;
      return Hop{port_to(from, m), dateline_class(from, to, dir)};
    }
    default: return grid_hop(from, to);
  }
}

}  // namespace topology
