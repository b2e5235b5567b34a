// The frame collector on node 0: gathers results into the frame.
//
// Reads Ports::collector on node 0:
//   result {first, count, colours} -> stored (each item exactly once)
// After the last item it sends frame_done to the farmer and ends; every
// result was sent before its worker asked for more work, so none can arrive
// later. progress(received, total) is called after each result.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/frame_assembler.hpp"
#include "nodes/messages.hpp"

namespace nodes {

using Progress = std::function<void(std::uint64_t done, std::uint64_t total)>;

class Collector {
 public:
  // owners, if given (one entry per item), receives the node that computed each item.
  Collector(FrameAssembler& frame, csp::In<Packet> in, Outbox out, Progress progress,
            std::vector<std::uint16_t>* owners = nullptr);
  void run();

 private:
  FrameAssembler& frame_;
  csp::In<Packet> in_;
  Outbox out_;
  Progress progress_;
  std::vector<std::uint16_t>* owners_;
};

}  // namespace nodes
