// The farmer (pixel server) on node 0: hands out tiles on request, passes
// results on to the frame collector and runs the orderly end of the machine.
//
// Reads Ports::farmer on node 0: a work_request for t tiles gets t answers
// and a result one (each work, or stop once the plan has no tile for that
// worker), sent to the asking port; each result then goes on to the
// collector. It counts worker_done, sends server_stop to every page server
// after the last one, and counts server_done. Answers to one worker go out
// in the order asked, and after a stop only stops follow. It ends once every
// worker and every page server is done, when nothing is in flight and every
// result has gone to the collector: it checks that the results cover the
// frame and calls on_quiet (the network's shutdown). The protocol:
// docs/architecture.md, "Messages" and "The orderly end".
#pragma once

#include <cstdint>
#include <functional>

#include "csp/csp.hpp"
#include "nodes/machine/messages.hpp"
#include "nodes/machine/work_plan.hpp"

namespace nodes {

struct FarmerCounters {
  std::uint64_t tiles = 0;
  std::uint64_t items = 0;  // items handed out
  std::uint64_t stops = 0;
  std::uint64_t results = 0;  // result packets passed to the collector
  std::uint64_t steals = 0;   // affinity schedule: tiles taken from another worker's share
};

class Farmer {
 public:
  Farmer(WorkPlan& plan, int nodes, int workers_per_node, csp::In<Packet> in, Outbox out,
         csp::Out<Packet> collector, std::function<void()> on_quiet, FarmerCounters& counters);
  void run();

 private:
  void answer(NodeId node, std::uint16_t port);
  void stop_servers();

  WorkPlan& plan_;
  int nodes_;
  int workers_per_node_;
  csp::In<Packet> in_;
  Outbox out_;
  csp::Out<Packet> collector_;
  std::function<void()> on_quiet_;
  FarmerCounters& counters_;
  std::uint64_t result_items_ = 0;
};

}  // namespace nodes
