// Item orders (see pixel_order.hpp). The Hilbert order is the generalised
// Hilbert curve for rectangles ("gilbert", J. Červený): a rectangle spanned
// by a major axis a and a minor axis b is split in two along a when it is
// much longer than wide, else into three parts (a first half along b, the
// rest along a, and a last half back along b), each traversed so that the
// parts join end to start. Halves are rounded so that the parts keep an
// even length where possible, which keeps every step a unit step except in
// the odd cases the header names.
//
// A walk's steps depend only on its axes, not on its corner, and the halving
// meets the same small rectangles over and over; so the steps of every small
// walk are kept, as offsets from its corner, and replayed when its axes come
// again. The order is the plain recursion's, item for item.
#include "nodes/machine/pixel_order.hpp"

#include <array>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

namespace nodes {

const char* pixel_order_name(PixelOrder order) {
  switch (order) {
    case PixelOrder::scanline: return "scanline";
    case PixelOrder::hilbert: return "hilbert";
  }
  return "?";
}

namespace {

int sign(int v) { return (v > 0) - (v < 0); }

// Halves towards minus infinity, so that a negative axis halves like a positive one mirrored.
int floor_half(int v) { return v >= 0 ? v / 2 : -((-v + 1) / 2); }

class HilbertWalk {
 public:
  HilbertWalk(int width, std::vector<std::uint32_t>& out) : width_(width), out_(out) {}

  // Visits the rectangle with corner (x, y), major axis (ax, ay) and minor
  // axis (bx, by); each axis is along x or y, its length the rectangle's side.
  void walk(int x, int y, int ax, int ay, int bx, int by) {
    const int w = std::abs(ax + ay), h = std::abs(bx + by);
    if (std::int64_t{w} * h > replay_area) return split(x, y, ax, ay, bx, by);
    const std::uint32_t corner = position(x, y);
    const Axes axes{ax, ay, bx, by};
    if (const auto kept = steps_.find(axes); kept != steps_.end()) {
      for (const std::uint32_t offset : kept->second) out_.push_back(corner + offset);
      return;
    }
    const std::size_t first = out_.size();
    split(x, y, ax, ay, bx, by);
    std::vector<std::uint32_t> offsets(out_.begin() + static_cast<std::ptrdiff_t>(first), out_.end());
    for (std::uint32_t& offset : offsets) offset -= corner;  // modulo 2^32, undone by the addition above
    steps_.emplace(axes, std::move(offsets));
  }

 private:
  using Axes = std::array<int, 4>;
  // Walks of at most this many cells are kept for replay.
  static constexpr int replay_area = 4096;

  void split(int x, int y, int ax, int ay, int bx, int by) {
    const int w = std::abs(ax + ay), h = std::abs(bx + by);
    const int dax = sign(ax), day = sign(ay), dbx = sign(bx), dby = sign(by);
    if (h == 1) {
      for (int i = 0; i < w; ++i, x += dax, y += day) emit(x, y);
      return;
    }
    if (w == 1) {
      for (int i = 0; i < h; ++i, x += dbx, y += dby) emit(x, y);
      return;
    }
    int ax2 = floor_half(ax), ay2 = floor_half(ay), bx2 = floor_half(bx), by2 = floor_half(by);
    const int w2 = std::abs(ax2 + ay2), h2 = std::abs(bx2 + by2);
    if (2 * w > 3 * h) {
      // Long and thin: two halves along the major axis.
      if (w2 % 2 != 0 && w > 2) ax2 += dax, ay2 += day;
      walk(x, y, ax2, ay2, bx, by);
      walk(x + ax2, y + ay2, ax - ax2, ay - ay2, bx, by);
      return;
    }
    if (h2 % 2 != 0 && h > 2) bx2 += dbx, by2 += dby;
    walk(x, y, bx2, by2, ax2, ay2);                       // up the first half of the minor axis
    walk(x + bx2, y + by2, ax, ay, bx - bx2, by - by2);  // across, on the rest of it
    walk(x + (ax - dax) + (bx2 - dbx), y + (ay - day) + (by2 - dby), -bx2, -by2, -(ax - ax2),
         -(ay - ay2));  // back down, beside the first part
  }

  std::uint32_t position(int x, int y) const {
    return static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(width_) + static_cast<std::uint32_t>(x);
  }
  void emit(int x, int y) { out_.push_back(position(x, y)); }

  int width_;
  std::vector<std::uint32_t>& out_;
  std::map<Axes, std::vector<std::uint32_t>> steps_;  // offsets from the corner, by axes
};

}  // namespace

std::vector<std::uint32_t> item_positions(int width, int height, PixelOrder order) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("pixel order: empty " + std::to_string(width) + "x" + std::to_string(height) +
                                " frame");
  std::vector<std::uint32_t> positions;
  if (order == PixelOrder::scanline) return positions;
  positions.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  HilbertWalk walk(width, positions);
  if (width >= height)
    walk.walk(0, 0, width, 0, 0, height);
  else
    walk.walk(0, 0, 0, height, width, 0);
  return positions;
}

}  // namespace nodes
