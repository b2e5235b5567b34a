// The farmer (pixel server) on node 0: hands out tiles on request and runs
// the orderly end of the machine (the protocol is in machine.hpp).
//
// Reads Ports::farmer on node 0:
//   work_request {port} from (s, port) -> work {tile} | stop   to (s, port)
//   worker_done                        -> count; after the last one,
//                                         server_stop to every page server
//   server_done                        -> count
//   frame_done (collector)             -> note
// Ends once every worker and every page server is done and the frame is
// complete: then nothing is in flight, and it calls on_quiet (the network's
// shutdown).
#pragma once

#include <cstdint>
#include <functional>

#include "csp/csp.hpp"
#include "nodes/messages.hpp"
#include "nodes/work_plan.hpp"

namespace nodes {

struct FarmerCounters {
  std::uint64_t tiles = 0;
  std::uint64_t items = 0;  // items handed out
  std::uint64_t stops = 0;
};

class Farmer {
 public:
  Farmer(WorkPlan& plan, int nodes, int workers_per_node, csp::In<Packet> in, Outbox out,
         std::function<void()> on_quiet, FarmerCounters& counters);
  void run();

 private:
  void answer(const Packet& request);
  void stop_servers();

  WorkPlan& plan_;
  int nodes_;
  int workers_per_node_;
  csp::In<Packet> in_;
  Outbox out_;
  std::function<void()> on_quiet_;
  FarmerCounters& counters_;
};

}  // namespace nodes
