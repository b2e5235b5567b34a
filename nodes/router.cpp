// Router process: ALT over link inputs, injections and link-process requests;
// bounded output queues; pending slots that hold back a full route.
#include "nodes/router.hpp"

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

Router::Router(topology::Topology topology, NodeId self, RouterEnds ends, RouterConfig config,
               RouterCounters& counters)
    : topology_(std::move(topology)),
      self_(self),
      ends_(std::move(ends)),
      config_(config),
      counters_(counters),
      link_queues_(ends_.inputs.size()),
      queues_(ends_.requests.size()),
      pending_(ends_.inputs.size() + ends_.injections.size()) {}

void Router::run() {
  build_alt();
  for (;;) {
    update_guards();
    const std::size_t guard = alt_.select();
    if (guard < request_guard_.size()) {
      send(guard);
      continue;
    }
    const std::size_t source = guard - request_guard_.size();
    Packet packet = source < ends_.inputs.size()
                        ? ends_.inputs[source].read()
                        : ends_.injections[source - ends_.inputs.size()].read();
    receive(source, std::move(packet));
  }
}

// Requests first, then sources (inputs, injections): guard index = position.
void Router::build_alt() {
  for (const auto& in : ends_.requests) request_guard_.push_back(alt_.add_input(in));
  for (const auto& in : ends_.inputs) source_guard_.push_back(alt_.add_input(in));
  for (const auto& in : ends_.injections) source_guard_.push_back(alt_.add_input(in));
}

void Router::update_guards() {
  for (std::size_t o = 0; o < queues_.size(); ++o) alt_.enable(request_guard_[o], !queues_[o].empty());
  for (std::size_t s = 0; s < pending_.size(); ++s)
    alt_.enable(source_guard_[s], !pending_[s].has_value());
}

void Router::receive(std::size_t source, Packet packet) {
  if (source >= ends_.inputs.size()) {
    accept_injection(packet);
  } else {
    ++packet.hops;
    if (packet.traced) packet.route.push_back(self_);
  }
  const std::size_t queue = output_queue(packet);
  if (queues_[queue].size() < config_.buffer_capacity) {
    if (queue >= link_queues_) note_delivery(packet); else ++counters_.forwarded;
    queues_[queue].push_back(std::move(packet));
  } else {
    pending_[source] = Pending{std::move(packet), queue};
    ++pending_count_;
  }
  note_occupancy();
}

void Router::accept_injection(Packet& packet) const {
  const std::size_t ports = queues_.size() - link_queues_;
  if (packet.destination >= topology_.size() || packet.port >= ports)
    throw std::out_of_range("node " + std::to_string(self_) + ": packet " +
                            std::to_string(packet.id) + " sent to node " +
                            std::to_string(packet.destination) + " port " +
                            std::to_string(packet.port) + ", which does not exist");
  ++counters_.injected;
  packet.source = self_;
  packet.hops = 0;
  packet.traced = packet.traced || packet.id < config_.trace_routes;
  packet.route.clear();
  if (packet.traced) packet.route.push_back(self_);
}

std::size_t Router::output_queue(const Packet& packet) const {
  if (packet.destination == self_) return link_queues_ + packet.port;
  const topology::Hop hop = topology_.next_hop(self_, packet.destination);
  return hop.port * topology_.buffer_classes() + hop.buffer_class;
}

// The link process of `queue` has asked (its request is ready): answer it.
void Router::send(std::size_t queue) {
  ends_.requests[queue].read();
  Packet packet = std::move(queues_[queue].front());
  queues_[queue].pop_front();
  ends_.replies[queue].write(std::move(packet));
  admit_pending(queue);
}

// A slot of `queue` is free: admit one pending packet waiting for it, taking
// the pending slots in rotation so that no input starves.
void Router::admit_pending(std::size_t queue) {
  if (pending_count_ == 0) return;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    const std::size_t s = (next_admit_ + k) % pending_.size();
    if (!pending_[s] || pending_[s]->queue != queue) continue;
    if (queue >= link_queues_) note_delivery(pending_[s]->packet); else ++counters_.forwarded;
    queues_[queue].push_back(std::move(pending_[s]->packet));
    pending_[s].reset();
    --pending_count_;
    next_admit_ = s + 1;
    return;
  }
}

void Router::note_delivery(const Packet& packet) {
  ++counters_.delivered;
  counters_.hops.add(packet.hops);
  counters_.hops_by_kind[packet.kind].add(packet.hops);
  if (packet.traced) counters_.routes.push_back(RouteRecord{packet.id, packet.kind, packet.route});
}

void Router::note_occupancy() {
  std::size_t total = pending_count_, longest = 0;
  for (const auto& q : queues_) {
    total += q.size();
    longest = std::max(longest, q.size());
  }
  counters_.peak_queued = std::max(counters_.peak_queued, static_cast<std::uint32_t>(total));
  counters_.peak_queue = std::max(counters_.peak_queue, static_cast<std::uint32_t>(longest));
}

}  // namespace nodes
