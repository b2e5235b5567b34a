// Router process: ALT over link inputs, injections and room in the outputs
// that held-back packets wait for; pending slots that hold back a full route.
#include "nodes/net/router.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace nodes {

void HopSummary::add(std::uint32_t hops) {
  ++packets;
  total_hops += hops;
  max_hops = std::max(max_hops, hops);
}

void HopSummary::merge(const HopSummary& other) {
  packets += other.packets;
  total_hops += other.total_hops;
  max_hops = std::max(max_hops, other.max_hops);
}

Router::Router(topology::Topology topology, NodeId self, RouterEnds ends, RouterConfig config, RouterCounters& counters)
    : self_(self),
      classes_(topology.buffer_classes()),
      link_queues_(ends.inputs.size()),
      topology_(std::move(topology)),
      held_(ends.inputs.size() + ends.injections.size(), 0),
      lanes_(ends.outputs.size()),
      ends_(std::move(ends)),
      pending_(held_.size()),
      config_(config),
      counters_(counters),
      log_(config.recorder ? &config.recorder->route_log(self) : nullptr) {
  counters_.sent.assign(ends_.outputs.size(), LinkCounters{});
}

void Router::run() {
  build_alt();
  for (;;) {
    const std::size_t guard = alt_.select();
    if (guard < room_guard_.size()) {
      admit_pending(guard);
      continue;
    }
    const std::size_t source = guard - room_guard_.size();
    Packet packet = source < ends_.inputs.size()
                        ? ends_.inputs[source].read()
                        : ends_.injections[source - ends_.inputs.size()].read();
    receive(source, packet);
  }
}

// Room guards first (one per output, enabled while a packet waits for it),
// then sources (inputs, injections): guard index = position.
void Router::build_alt() {
  for (const auto& out : ends_.outputs) {
    room_guard_.push_back(alt_.add_room(out));
    alt_.enable(room_guard_.back(), false);
  }
  for (const auto& in : ends_.inputs) source_guard_.push_back(alt_.add_input(in));
  for (const auto& in : ends_.injections) source_guard_.push_back(alt_.add_input(in));
}

void Router::forward_in_place(std::size_t queue, Router& next, std::size_t input) {
  if (queue >= link_queues_ || input >= next.ends_.inputs.size())
    throw std::logic_error("router " + std::to_string(self_) + ": no link queue " + std::to_string(queue) +
                           " into input " + std::to_string(input) + " of router " + std::to_string(next.self_));
  lanes_[queue].next = &next;
  lanes_[queue].next_input = static_cast<std::uint32_t>(input);
}

void Router::receive_in_place(std::size_t port, PortReceiver& receiver) {
  if (port >= lanes_.size() - link_queues_)
    throw std::logic_error("router " + std::to_string(self_) + ": no local port " + std::to_string(port));
  lanes_[link_queues_ + port].receiver = &receiver;
}

void Router::send_across(std::size_t queue, PortReceiver& sender) {
  if (queue >= link_queues_ || lanes_[queue].next)
    throw std::logic_error("router " + std::to_string(self_) + ": no link queue " + std::to_string(queue) +
                           " to another thread");
  lanes_[queue].receiver = &sender;
}

bool Router::inject_in_place(Packet& packet) {
  const std::size_t source = ends_.inputs.size();  // the injection channel
  std::size_t queue = 0;
  if (!valid_injection(packet) || !takes_at_once(source, packet, queue)) return false;
  accept_injection(packet);
  ++counters_.in_place;
  if (!try_send(queue, packet))
    throw std::logic_error("router " + std::to_string(self_) + ": an output with room refused a packet");
  return true;
}

bool Router::take_in_place(std::size_t input, Packet& packet) {
  std::size_t queue = 0;
  if (input >= ends_.inputs.size() || !takes_at_once(input, packet, queue)) return false;
  arrive(packet);
  ++counters_.in_place;
  if (!try_send(queue, packet))
    throw std::logic_error("router " + std::to_string(self_) + ": an output with room refused a packet");
  return true;
}

void Router::receive(std::size_t source, Packet& packet) {
  if (source >= ends_.inputs.size())
    accept_injection(packet);
  else
    arrive(packet);
  const std::size_t queue = output_queue(packet);
  // Packets already held back for this output go first.
  if (lanes_[queue].held_for > 0 || !try_send(queue, packet)) hold(source, packet, queue);
}

// A packet read from a link input: one more hop.
void Router::arrive(Packet& packet) {
  ++packet.hops;
  if (packet.traced) packet.route.push_back(self_);
  if (log_ && packet.recorded) log_->arrived.push_back({packet.id, config_.recorder->now(), 0, packet.hops});
}

bool Router::valid_injection(const Packet& packet) const {
  return packet.destination < topology_.size() && packet.port < ends_.outputs.size() - link_queues_;
}

void Router::accept_injection(Packet& packet) const {
  if (!valid_injection(packet))
    throw std::out_of_range("node " + std::to_string(self_) + ": packet " +
                            std::to_string(packet.id) + " sent to node " +
                            std::to_string(packet.destination) + " port " +
                            std::to_string(packet.port) + ", which does not exist");
  ++counters_.injected;
  packet.source = self_;
  packet.hops = 0;
  packet.traced = packet.traced || take_route_to_trace(packet.kind);
  packet.route.clear();
  if (packet.traced) packet.route.push_back(self_);
  packet.recorded = log_ && config_.recorder->admit();
  if (packet.recorded)
    log_->injected.push_back({packet.id, config_.recorder->now(), packet.destination,
                              static_cast<std::uint32_t>(packet.bytes()), packet.kind});
}

bool Router::take_route_to_trace(std::uint8_t kind) const {
  if (config_.routes_to_trace == nullptr) return false;
  if (config_.kinds_to_trace != nullptr && !(*config_.kinds_to_trace)[kind]) return false;
  std::uint64_t left = config_.routes_to_trace->load(std::memory_order_relaxed);
  while (left > 0)
    if (config_.routes_to_trace->compare_exchange_weak(left, left - 1, std::memory_order_relaxed)) return true;
  return false;
}

std::size_t Router::output_queue(const Packet& packet) const {
  if (packet.destination == self_) return link_queues_ + packet.port;
  const topology::Hop hop = topology_.next_hop(self_, packet.destination);
  return hop.port * classes_ + hop.buffer_class;
}

// Whether this router's own step would send the packet, arriving now by
// `source`, straight on: nothing from that source ahead of it (queued or
// held back), nothing held back for its output, and room there, which
// stays until this router writes (it is the output's only writer). Both
// ends of `source` run on the caller's thread, so its hint is exact.
bool Router::takes_at_once(std::size_t source, const Packet& packet, std::size_t& queue) const {
  if (held_[source]) return false;
  const csp::In<Packet>& in =
      source < ends_.inputs.size() ? ends_.inputs[source] : ends_.injections[source - ends_.inputs.size()];
  if (in.ready_hint()) return false;  // values ahead of it, or poison
  queue = output_queue(packet);
  const csp::Out<Packet>& out = ends_.outputs[queue];
  return lanes_[queue].held_for == 0 && out.room_hint() && !out.poisoned();
}

// Writes the packet into its output queue if that has room; false (packet
// untouched) if it is full. Where the queue leads to a router of this
// thread that would send the packet straight on, the packet goes through
// that router's step in place instead, with the same counts, and so on:
// only the first queue can be full.
bool Router::try_send(std::size_t queue, Packet& packet) {
  Router* at = this;
  for (;;) {
    const OutLane& lane = at->lanes_[queue];
    Router* next = lane.next;
    std::size_t next_queue = 0;
    if (!next || !next->takes_at_once(lane.next_input, packet, next_queue)) {
      if (at->write_out(queue, packet)) return true;
      if (at == this) return false;
      throw std::logic_error("router " + std::to_string(at->self_) + ": an output with room refused a packet");
    }
    const double left_at = at->log_ && packet.recorded ? at->config_.recorder->now() : 0.0;
    std::optional<RouteRecord> no_route;
    at->count_sent(queue, packet.bytes(), packet.hops, packet.kind, packet.recorded, packet.id, left_at, no_route);
    next->arrive(packet);
    ++next->counters_.in_place;
    at = next;
    queue = next_queue;
  }
}

// The channel write of try_send, and its counts; or a delivery taken in
// place by the port's receiver, or a packet by a relayed link's sender,
// counted first, as the far side may read it at once.
bool Router::write_out(std::size_t queue, Packet& packet) {
  const std::size_t bytes = packet.bytes();
  const std::uint16_t hops = packet.hops;
  const std::uint8_t kind = packet.kind;
  const bool recorded = packet.recorded;
  const std::uint64_t id = packet.id;
  // Before the write: on another thread the next router may read it at once.
  const double left_at = log_ && recorded ? config_.recorder->now() : 0.0;
  std::optional<RouteRecord> route;
  if (queue >= link_queues_ && packet.traced) route = RouteRecord{packet.id, packet.kind, packet.route};
  PortReceiver* receiver = lanes_[queue].receiver;
  if (receiver && receiver->takes_at_once(packet)) {
    count_sent(queue, bytes, hops, kind, recorded, id, left_at, route);
    receiver->take(packet);
    return true;
  }
  if (!ends_.outputs[queue].try_write(packet)) return false;
  count_sent(queue, bytes, hops, kind, recorded, id, left_at, route);
  return true;
}

void Router::count_sent(std::size_t queue, std::size_t bytes, std::uint16_t hops, std::uint8_t kind, bool recorded,
                        std::uint64_t id, double left_at, std::optional<RouteRecord>& route) {
  ++counters_.sent[queue].packets;
  counters_.sent[queue].bytes += bytes;
  if (log_) record_sent(recorded, id, hops, kind, queue, left_at);
  if (queue < link_queues_) {
    ++counters_.forwarded;
    return;
  }
  ++counters_.delivered;
  counters_.hops.add(hops);
  counters_.hops_by_kind[kind].add(hops);
  if (route) counters_.routes.push_back(std::move(*route));
}

// Off the hot path: only a recorded run calls it.
void Router::record_sent(bool recorded, std::uint64_t id, std::uint16_t hops, std::uint8_t kind, std::size_t queue,
                         double time) {
  const bool delivery = queue >= link_queues_;
  if (!recorded) {
    if (delivery) {
      ++log_->unrecorded[kind];
      log_->unrecorded_hops += hops;
    }
    return;
  }
  if (delivery)
    log_->delivered.push_back({id, time, hops});
  else
    log_->departed.push_back({id, time, static_cast<std::uint32_t>(queue), hops});
}

void Router::hold(std::size_t source, Packet& packet, std::size_t queue) {
  pending_[source] = Pending{std::move(packet), queue};
  held_[source] = 1;
  alt_.enable(source_guard_[source], false);
  if (lanes_[queue].held_for++ == 0) alt_.enable(room_guard_[queue], true);
  counters_.peak_pending = std::max(counters_.peak_pending, ++pending_count_);
}

// `queue` has room: write the packets held back for it while it has, taking
// the pending slots in rotation so that no input starves.
void Router::admit_pending(std::size_t queue) {
  for (std::size_t k = 0; k < pending_.size() && lanes_[queue].held_for > 0; ++k) {
    const std::size_t s = (next_admit_ + k) % pending_.size();
    if (!held_[s] || pending_[s].queue != queue) continue;
    if (!try_send(queue, pending_[s].packet)) return;
    held_[s] = 0;
    pending_[s].packet = Packet{};  // what try_send left of it
    alt_.enable(source_guard_[s], true);
    --pending_count_;
    if (--lanes_[queue].held_for == 0) alt_.enable(room_guard_[queue], false);
    next_admit_ = s + 1;
  }
}

}  // namespace nodes
