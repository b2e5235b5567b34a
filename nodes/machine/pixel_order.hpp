// The order in which the farmer's items (pixels, or SPD corner samples) are
// numbered, and so the shape of a tile: a tile is always a contiguous run of
// item numbers (work_plan.hpp), and the order decides where on the frame
// that run lies.
//  - scanline: item i is pixel (i mod W, i div W), as in the paper; a tile
//    is a piece of a row.
//  - hilbert: items follow a generalised Hilbert curve over the W x H frame,
//    so that any run of items — a dynamic tile, a static or affinity share —
//    is a compact patch of the frame rather than a band. Neighbouring rays
//    then share more pages, and a processor's cache holds its patch.
// Invariants: item_positions() is a permutation of 0 .. W*H-1 (each
// scanline position exactly once); consecutive hilbert items are at most one
// step apart (a diagonal step only where W or H is odd); on a 2^k x 2^k
// frame it is the classic Hilbert curve, every step to a 4-neighbour.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace nodes {

enum class PixelOrder { scanline, hilbert };

// The order's name: scanline or hilbert.
const char* pixel_order_name(PixelOrder order);

// Item k's scanline position (y * width + x), for every item of a
// width x height grid. Empty for scanline order, where the position is k.
std::vector<std::uint32_t> item_positions(int width, int height, PixelOrder order);

// Item `item`'s scanline position, given item_positions()'s table.
inline std::uint32_t scanline_position(std::span<const std::uint32_t> positions, std::uint32_t item) {
  return positions.empty() ? item : positions[item];
}

}  // namespace nodes
