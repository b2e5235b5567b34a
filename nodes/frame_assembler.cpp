// Frame collector bookkeeping (see frame_assembler.hpp).
#include "nodes/frame_assembler.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

FrameAssembler::FrameAssembler(std::uint32_t items) : colors_(items), arrived_(items, false) {}

void FrameAssembler::add(const ResultView& result) {
  const std::uint64_t end = std::uint64_t{result.tile.first} + result.tile.count;
  if (end > colors_.size())
    throw std::logic_error("result for items beyond the frame: " + std::to_string(end));
  for (std::uint32_t i = 0; i < result.tile.count; ++i) {
    const std::uint32_t item = result.tile.first + i;
    if (arrived_[item]) throw std::logic_error("item " + std::to_string(item) + " computed twice");
    arrived_[item] = true;
    colors_[item] = result.color(i);
  }
  received_ += result.tile.count;
}

}  // namespace nodes
