// Page server process (see page_server.hpp).
#include "nodes/machine/page_server.hpp"

#include <span>
#include <stdexcept>
#include <string>


namespace nodes {

PageServer::PageServer(NodeId node, const NodeMemory& memory, csp::In<Packet> requests, Outbox out,
                       ServerCounters& counters, std::function<void()> before_reply, Recorder* recorder)
    : node_(node),
      memory_(memory),
      requests_(std::move(requests)),
      out_(std::move(out)),
      counters_(counters),
      before_reply_(std::move(before_reply)),
      recorder_(recorder) {}

void PageServer::run() {
  for (;;) {
    Packet packet = requests_.read();
    switch (static_cast<MessageKind>(packet.kind)) {
      case MessageKind::page_request:
        serve(packet);
        break;
      case MessageKind::server_stop:
        out_.send(make_packet(0, Ports::farmer, MessageKind::server_done));
        return;
      default:
        throw std::logic_error("page server got a " + std::string(message_kind_name(packet.kind)) + " message");
    }
  }
}

bool PageServer::takes_at_once(const Packet& packet) const {
  return !serving_ && packet.kind == static_cast<std::uint8_t>(MessageKind::page_request) &&
         !requests_.ready_hint() && out_.room_hint();
}

void PageServer::take(Packet& packet) {
  serve(packet);
  ++counters_.served_in_place;
}

void PageServer::serve(const Packet& request) {
  serving_ = true;
  const bool record = recorder_ && recorder_->open();
  if (recorder_ && !record) ++recorder_->log(node_).unrecorded_serves;
  const double start = record ? recorder_->now() : 0.0;
  const PageRequest r = decode_page_request(request.payload);
  const std::int32_t entry = memory_.entry(r.page);
  if (entry < 0)
    throw std::logic_error("node " + std::to_string(node_) + " asked for page " + std::to_string(r.page) +
                           " it does not own");
  const std::span<const std::byte> bytes(memory_.own_page(entry), memory_.page_size());
  if (before_reply_) before_reply_();
  out_.send(make_page_reply(request.source, r.reply_port, r.page, bytes));
  ++counters_.pages_served;
  counters_.bytes_served += bytes.size();
  if (record) recorder_->log(node_).serves.push_back({start, recorder_->now(), r.page, request.source});
  serving_ = false;
}

}  // namespace nodes
