// The page server of a processor: answers page requests for the pages this
// processor owns, for any worker of any node (its own included).
// Protocol: reads its local port (Ports::page_server).
//   page_request {page, reply port} from node s -> page_reply {page, bytes}
//                                                  to (s, reply port)
//   server_stop from the farmer -> server_done to the farmer, then ends.
// Each request is answered before the next is read; it waits for nothing but
// the network. server_stop comes only once every worker has stopped. Where
// routers route in place, the server is also its port's receiver
// (PortReceiver): a request that finds it idle, its port empty and the
// node's injection channel with room is served at once by its deliverer.
// Requests may then be served out of their order of arrival: each comes
// from a pixel computer with no other request outstanding.
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
  std::uint64_t served_in_place = 0;  // of pages_served, served by the request's deliverer
};

class PageServer final : public PortReceiver {
 public:
  PageServer(NodeId node, const NodeMemory& memory, csp::In<Packet> requests, Outbox out, ServerCounters& counters,
             std::function<void()> before_reply = {}, Recorder* recorder = nullptr);
  void run();

  // PortReceiver: a page request while no other is being served, none is
  // queued, and the reply's send cannot wait.
  bool takes_at_once(const Packet& packet) const override;
  void take(Packet& packet) override;

 private:
  void serve(const Packet& request);

  NodeId node_;
  const NodeMemory& memory_;
  csp::In<Packet> requests_;
  Outbox out_;
  ServerCounters& counters_;
  std::function<void()> before_reply_;  // virtual time charges the handler here
  Recorder* recorder_;                  // set: each request served goes into the node's log
  bool serving_ = false;                // inside serve(), by the server or a deliverer
};

}  // namespace nodes
