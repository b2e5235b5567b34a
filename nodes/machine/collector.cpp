// Frame collector process (see collector.hpp).
#include "nodes/machine/collector.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

Collector::Collector(FrameAssembler& frame, csp::In<Packet> in, Progress progress, std::vector<std::uint16_t>* owners)
    : frame_(frame), in_(std::move(in)), progress_(std::move(progress)), owners_(owners) {}

void Collector::run() {
  if (progress_) progress_(0, frame_.items());  // the machine is built and running
  while (!frame_.complete()) {
    const Packet packet = in_.read();
    if (static_cast<MessageKind>(packet.kind) != MessageKind::result)
      throw std::logic_error("collector got a " + std::string(message_kind_name(packet.kind)) + " message");
    const ResultView result = decode_result(packet.payload);
    frame_.add(result);
    if (owners_)
      for (std::uint32_t i = 0; i < result.tile.count; ++i)
        (*owners_)[frame_.position(result.tile.first + i)] = static_cast<std::uint16_t>(packet.source);
    if (progress_) progress_(frame_.received(), frame_.items());
  }
}

}  // namespace nodes
