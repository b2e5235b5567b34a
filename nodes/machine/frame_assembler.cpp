// Frame collector bookkeeping (see frame_assembler.hpp).
#include "nodes/machine/frame_assembler.hpp"

#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace nodes {

FrameAssembler::FrameAssembler(std::uint32_t items, std::span<const std::uint32_t> positions)
    : positions_(positions), colors_(items), arrived_(items, 0) {
  if (!positions_.empty() && positions_.size() != items)
    throw std::logic_error("pixel order of " + std::to_string(positions_.size()) + " items for a frame of " +
                           std::to_string(items));
}

// A result's colours are its tile's Colors byte for byte (messages.hpp), so
// each is copied straight into its place in the frame.
void FrameAssembler::add(const ResultView& result) {
  static_assert(std::is_trivially_copyable_v<tracer::Color>);
  const std::uint64_t end = std::uint64_t{result.tile.first} + result.tile.count;
  if (end > colors_.size())
    throw std::logic_error("result for items beyond the frame: " + std::to_string(end));
  if (result.rgb.size() != std::size_t{result.tile.count} * sizeof(tracer::Color))
    throw std::logic_error("result of " + std::to_string(result.tile.count) + " items with " +
                           std::to_string(result.rgb.size()) + " bytes of colour");
  const std::byte* rgb = result.rgb.data();
  for (std::uint32_t i = 0; i < result.tile.count; ++i) {
    const std::uint32_t item = result.tile.first + i;
    const std::uint32_t at = position(item);
    if (arrived_[at]) throw std::logic_error("item " + std::to_string(item) + " computed twice");
    arrived_[at] = 1;
    std::memcpy(&colors_[at], rgb + std::size_t{i} * sizeof(tracer::Color), sizeof(tracer::Color));
  }
  received_ += result.tile.count;
}

}  // namespace nodes
