// The page server of a processor: answers page requests for the pages this
// processor owns, for any worker of any node (its own included).
//
// Protocol: reads its local port (Ports::page_server).
//   page_request {page, reply port} from node s -> page_reply {page, bytes}
//                                                  to (s, reply port)
//   server_stop from the farmer -> server_done to the farmer, then ends.
// Every request is answered before the next is read; it never waits for
// anything but the network, so it keeps serving while the node's own workers
// block on their misses. The farmer sends server_stop only once every worker
// of the machine has stopped, so no request can arrive after it.
#pragma once

#include <cstdint>
#include <functional>

#include "csp/csp.hpp"
#include "nodes/machine/messages.hpp"
#include "nodes/machine/node_memory.hpp"
#include "nodes/machine/recorder.hpp"
#include "nodes/net/packet.hpp"

namespace nodes {

struct ServerCounters {
  std::uint64_t pages_served = 0;  // page communications
  std::uint64_t bytes_served = 0;  // page bytes sent
};

class PageServer {
 public:
  PageServer(NodeId node, const NodeMemory& memory, csp::In<Packet> requests, Outbox out, ServerCounters& counters,
             std::function<void()> before_reply = {}, Recorder* recorder = nullptr);
  void run();

 private:
  void serve(const Packet& request);

  NodeId node_;
  const NodeMemory& memory_;
  csp::In<Packet> requests_;
  Outbox out_;
  ServerCounters& counters_;
  std::function<void()> before_reply_;  // virtual time charges the handler here
  Recorder* recorder_;                  // set: each request served goes into the node's log
};

}  // namespace nodes
