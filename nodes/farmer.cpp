// Farmer process (see farmer.hpp).
#include "nodes/farmer.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

Farmer::Farmer(WorkPlan& plan, int nodes, int workers_per_node, csp::In<Packet> in, Outbox out,
               std::function<void()> on_quiet, FarmerCounters& counters)
    : plan_(plan),
      nodes_(nodes),
      workers_per_node_(workers_per_node),
      in_(std::move(in)),
      out_(std::move(out)),
      on_quiet_(std::move(on_quiet)),
      counters_(counters) {}

void Farmer::run() {
  int workers_left = nodes_ * workers_per_node_;
  int servers_left = nodes_;
  bool frame_done = false;
  while (workers_left > 0 || servers_left > 0 || !frame_done) {
    const Packet packet = in_.read();
    switch (static_cast<MessageKind>(packet.kind)) {
      case MessageKind::work_request:
        answer(packet);
        break;
      case MessageKind::worker_done:
        // All workers stopped: every page request has been answered.
        if (--workers_left == 0) stop_servers();
        break;
      case MessageKind::server_done:
        --servers_left;
        break;
      case MessageKind::frame_done:
        frame_done = true;
        break;
      default:
        throw std::logic_error("farmer got a " + std::string(message_kind_name(packet.kind)) + " message");
    }
  }
  on_quiet_();
}

void Farmer::answer(const Packet& request) {
  const std::uint16_t port = decode_port(request.payload);
  const auto tile = plan_.next(static_cast<int>(request.source), port - Ports::first_worker);
  if (!tile) {
    ++counters_.stops;
    out_.send(make_packet(request.source, port, MessageKind::stop));
    return;
  }
  ++counters_.tiles;
  counters_.items += tile->count;
  out_.send(make_packet(request.source, port, MessageKind::work, encode_tile(*tile)));
}

void Farmer::stop_servers() {
  for (int n = 0; n < nodes_; ++n)
    out_.send(make_packet(static_cast<NodeId>(n), Ports::page_server, MessageKind::server_stop));
}

}  // namespace nodes
