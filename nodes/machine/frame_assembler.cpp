// Frame collector bookkeeping (see frame_assembler.hpp).
#include "nodes/machine/frame_assembler.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

FrameAssembler::FrameAssembler(std::uint32_t items, std::span<const std::uint32_t> positions)
    : positions_(positions), colors_(items), arrived_(items, false) {
  if (!positions_.empty() && positions_.size() != items)
    throw std::logic_error("pixel order of " + std::to_string(positions_.size()) + " items for a frame of " +
                           std::to_string(items));
}

void FrameAssembler::add(const ResultView& result) {
  const std::uint64_t end = std::uint64_t{result.tile.first} + result.tile.count;
  if (end > colors_.size())
    throw std::logic_error("result for items beyond the frame: " + std::to_string(end));
  for (std::uint32_t i = 0; i < result.tile.count; ++i) {
    const std::uint32_t item = result.tile.first + i;
    const std::uint32_t at = position(item);
    if (arrived_[at]) throw std::logic_error("item " + std::to_string(item) + " computed twice");
    arrived_[at] = true;
    colors_[at] = result.color(i);
  }
  received_ += result.tile.count;
}

}  // namespace nodes
