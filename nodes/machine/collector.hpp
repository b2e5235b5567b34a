// The frame collector on node 0: gathers results into the frame.
//
// Reads the local channel from the farmer (not a network port):
//   result {port, first, count, colours} -> stored (each item exactly once)
// Ends after the last item. progress(received, total) is called once with
// received 0 as it starts (every process of the machine is running), then
// after each result.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/machine/frame_assembler.hpp"
#include "nodes/machine/messages.hpp"

namespace nodes {

using Progress = std::function<void(std::uint64_t done, std::uint64_t total)>;

class Collector {
 public:
  // owners, if given (one entry per item, in scanline order like the frame), receives the node that
  // computed each item.
  Collector(FrameAssembler& frame, csp::In<Packet> in, Progress progress, std::vector<std::uint16_t>* owners = nullptr);
  void run();

 private:
  FrameAssembler& frame_;
  csp::In<Packet> in_;
  Progress progress_;
  std::vector<std::uint16_t>* owners_;
};

}  // namespace nodes
