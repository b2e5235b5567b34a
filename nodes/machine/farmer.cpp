// Farmer process (see farmer.hpp).
#include "nodes/machine/farmer.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

Farmer::Farmer(WorkPlan& plan, int nodes, int workers_per_node, csp::In<Packet> in, Outbox out,
               csp::Out<Packet> collector, std::function<void()> on_quiet, FarmerCounters& counters)
    : plan_(plan),
      nodes_(nodes),
      workers_per_node_(workers_per_node),
      in_(std::move(in)),
      out_(std::move(out)),
      collector_(std::move(collector)),
      on_quiet_(std::move(on_quiet)),
      counters_(counters) {}

void Farmer::run() {
  int workers_left = nodes_ * workers_per_node_;
  int servers_left = nodes_;
  while (workers_left > 0 || servers_left > 0) {
    Packet packet = in_.read();
    switch (static_cast<MessageKind>(packet.kind)) {
      case MessageKind::work_request: {
        const WorkRequest request = decode_work_request(packet.payload);
        for (std::uint16_t i = 0; i < request.tiles; ++i) answer(packet.source, request.reply_port);
        break;
      }
      case MessageKind::result: {
        const ResultView result = decode_result(packet.payload);
        answer(packet.source, result.reply_port);
        ++counters_.results;
        result_items_ += result.tile.count;
        collector_.write(std::move(packet));
        break;
      }
      case MessageKind::worker_done:
        // All workers stopped: every page request has been answered.
        if (--workers_left == 0) stop_servers();
        break;
      case MessageKind::server_done:
        --servers_left;
        break;
      default:
        throw std::logic_error("farmer got a " + std::string(message_kind_name(packet.kind)) + " message");
    }
  }
  if (result_items_ != plan_.items())
    throw std::logic_error("farmer: every worker is done but results cover " + std::to_string(result_items_) +
                           " of " + std::to_string(plan_.items()) + " items");
  on_quiet_();
}

void Farmer::answer(NodeId node, std::uint16_t port) {
  const auto tile = plan_.next(static_cast<int>(node), port - Ports::first_worker);
  if (!tile) {
    ++counters_.stops;
    out_.send(make_packet(node, port, MessageKind::stop));
    return;
  }
  ++counters_.tiles;
  counters_.items += tile->count;
  out_.send(make_packet(node, port, MessageKind::work, encode_tile(*tile)));
}

void Farmer::stop_servers() {
  for (int n = 0; n < nodes_; ++n)
    out_.send(make_packet(static_cast<NodeId>(n), Ports::page_server, MessageKind::server_stop));
}

}  // namespace nodes
