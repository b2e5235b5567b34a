// The frame collector's bookkeeping, without fibers: stores each arriving
// item's colour (a pixel, or an SPD corner sample) at its place in the
// frame and checks that every item arrives exactly once.
//
// Invariants: received() counts distinct items; an item outside the frame or
// arriving twice is a protocol error (std::logic_error), never silently
// overwritten; complete() once received() == items(); colors() is in
// scanline order whatever the pixel order the items are numbered in.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "nodes/machine/messages.hpp"
#include "nodes/machine/pixel_order.hpp"
#include "tracer/vec.hpp"

namespace nodes {

class FrameAssembler {
 public:
  // positions: item -> scanline position (pixel_order.hpp); empty when items are in scanline order.
  explicit FrameAssembler(std::uint32_t items, std::span<const std::uint32_t> positions = {});

  void add(const ResultView& result);

  std::uint32_t items() const { return static_cast<std::uint32_t>(colors_.size()); }
  std::uint32_t received() const { return received_; }
  bool complete() const { return received_ == colors_.size(); }
  const std::vector<tracer::Color>& colors() const { return colors_; }
  std::vector<tracer::Color> take_colors() { return std::move(colors_); }  // leaves none
  std::uint32_t position(std::uint32_t item) const { return scanline_position(positions_, item); }

 private:
  std::span<const std::uint32_t> positions_;
  std::vector<tracer::Color> colors_;
  std::vector<std::uint8_t> arrived_;  // by scanline position: its colour has come
  std::uint32_t received_ = 0;
};

}  // namespace nodes
