// The router of one processor: store-and-forward switching by the topology's
// deadlock-free routing function (docs/architecture.md, "Why the network
// cannot deadlock", and "Steps taken in place").
// Ends: inputs[p * classes + c] (link port p, buffer class c), injections
// from the node's processes, outputs (bounded, capacity K): the link queues
// numbered as the inputs, then one delivery queue per local port.
// Protocol: one doorbell ALT over the inputs and a room guard per output a
// held-back packet waits for. A packet goes out with try_write at once, or
// waits in its input's pending slot; held-back packets are admitted in
// rotation, so each (link, class) owns at most K queued + 1 pending packets.
// A writer on the router's thread takes the router's step in place when the
// router would send the packet straight on; a port's registered receiver
// takes a delivery in place when its queue is empty. Consumption assumption:
// a delivery queue drains while its reader reads.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/link.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/net/route_log.hpp"
#include "topology/topology.hpp"

namespace nodes {

struct HopSummary {
  std::uint64_t packets = 0;
  std::uint64_t total_hops = 0;
  std::uint32_t max_hops = 0;

  void add(std::uint32_t hops);
  void merge(const HopSummary& other);
  double mean() const { return packets ? static_cast<double>(total_hops) / packets : 0.0; }
};

struct RouteRecord {
  std::uint64_t id = 0;
  std::uint8_t kind = 0;
  std::vector<NodeId> route;
};

// Owned by one router process; read only after the runtime has stopped.
struct RouterCounters {
  std::uint64_t injected = 0;
  std::uint64_t forwarded = 0;  // packets sent on into a link queue
  std::uint64_t delivered = 0;
  std::uint64_t in_place = 0;   // packets taken without a channel read: routed in place by a sender
  std::uint32_t peak_pending = 0;  // most packets held back at once (outputs full)
  std::vector<LinkCounters> sent;  // per output queue: packets and payload bytes
  HopSummary hops;                 // of packets delivered here
  std::array<HopSummary, 256> hops_by_kind{};  // index = packet kind
  std::vector<RouteRecord> routes;  // traced packets delivered here
};

struct RouterEnds {
  std::vector<csp::In<Packet>> inputs;
  std::vector<csp::In<Packet>> injections;
  std::vector<csp::Out<Packet>> outputs;  // buffered channels
};

struct RouterConfig {
  // Routes still to trace, shared by every router of the network: each
  // injection takes one while any are left, so the first packets injected
  // are traced, however their senders number them. Null: none traced.
  std::atomic<std::uint64_t>* routes_to_trace = nullptr;
  // The packet kinds traced, by kind; null: every kind. Packets of other
  // kinds take no route from routes_to_trace.
  const std::array<bool, 256>* kinds_to_trace = nullptr;
  // The run's recorder (route_log.hpp), whose log of this node only this
  // router writes; null: nothing recorded, one branch per packet.
  RouteRecorder* recorder = nullptr;
};

// A local process that can take a packet delivered to its port in place of
// reading it, called on the router's thread by whoever takes the router's
// last step (Router::receive_in_place). take() must not suspend: whoever
// calls it may be a router's step or another process's send.
class PortReceiver {
 public:
  virtual ~PortReceiver() = default;
  // Whether take() would handle this packet now, at once: the port's queue
  // is empty and nothing it would do waits. A packet taken so overtakes
  // none queued, but may overtake one already handed to the port's parked
  // reader and not yet handled: a receiver takes only packets whose order
  // against those does not matter.
  virtual bool takes_at_once(const Packet& packet) const = 0;
  virtual void take(Packet& packet) = 0;
};

class Router {
 public:
  Router(topology::Topology topology, NodeId self, RouterEnds ends, RouterConfig config,
         RouterCounters& counters);
  void run();

  // Before run(): output queue `queue` is input `input` of `next`, which
  // runs on this router's thread; packets then go through next's step in
  // place when it could take them at once.
  void forward_in_place(std::size_t queue, Router& next, std::size_t input);
  // From a process on this router's thread: routes an injected packet at
  // once, as if the router had read it, when nothing is ahead of it and its
  // output has room; false, the packet untouched, otherwise (write it to
  // the injection channel then).
  bool inject_in_place(Packet& packet);
  // The same for a packet arriving on link input `input`, from a process
  // of this router's thread that is that input's only writer (a relay).
  bool take_in_place(std::size_t input, Packet& packet);
  // Before run(): deliveries to local `port` go to `receiver` whenever it
  // takes them at once, counted as deliveries; otherwise into the port.
  void receive_in_place(std::size_t port, PortReceiver& receiver);
  // Before run(): output queue `queue`, a link whose far end is on another
  // thread, goes to `sender` whenever it takes a packet at once (the
  // relays' sender(), thread_relay.hpp), counted as forwarded; otherwise
  // into the queue.
  void send_across(std::size_t queue, PortReceiver& sender);

 private:
  struct Pending {
    Packet packet;
    std::size_t queue = 0;
  };
  // What a step in place reads of one output, in one place.
  struct OutLane {
    std::uint32_t held_for = 0;        // pending packets waiting for this output
    std::uint32_t next_input = 0;
    Router* next = nullptr;            // set: the queue is next's input next_input, on this thread
    PortReceiver* receiver = nullptr;  // who takes in place: a port's receiver, a relayed link's sender; or none
  };

  void build_alt();
  void receive(std::size_t source, Packet& packet);
  void accept_injection(Packet& packet) const;
  void record_sent(bool recorded, std::uint64_t id, std::uint16_t hops, std::uint8_t kind, std::size_t queue,
                   double time);
  bool take_route_to_trace(std::uint8_t kind) const;
  bool try_send(std::size_t queue, Packet& packet);
  bool write_out(std::size_t queue, Packet& packet);
  void count_sent(std::size_t queue, std::size_t bytes, std::uint16_t hops, std::uint8_t kind, bool recorded,
                  std::uint64_t id, double left_at, std::optional<RouteRecord>& route);
  bool takes_at_once(std::size_t source, const Packet& packet, std::size_t& queue) const;
  void arrive(Packet& packet);
  bool valid_injection(const Packet& packet) const;
  void hold(std::size_t source, Packet& packet, std::size_t queue);
  void admit_pending(std::size_t queue);
  std::size_t output_queue(const Packet& packet) const;

  // The fields a step in place reads come first, together.
  NodeId self_;
  unsigned classes_;         // the topology's buffer classes
  std::size_t link_queues_;  // degree * classes; delivery queues follow
  topology::Topology topology_;
  std::vector<std::uint8_t> held_;  // per input, then per injection: a packet waits in pending_
  std::vector<OutLane> lanes_;      // per output
  RouterEnds ends_;
  std::vector<Pending> pending_;    // per input, then per injection; meaningful where held_
  RouterConfig config_;
  RouterCounters& counters_;
  RouteLog* log_ = nullptr;   // this node's log when the run is recorded
  std::uint32_t pending_count_ = 0;
  std::size_t next_admit_ = 0;  // rotates which pending packet is admitted first
  csp::Alt alt_{csp::Alt::Waiting::doorbell};
  std::vector<std::size_t> room_guard_, source_guard_;
};

// A local process's way into the network at its node, used only by
// processes on the node's thread: a write routes the packet in place when
// the router could take it at once (network.hpp, NetworkOptions::forward_in_place),
// else writes it to the node's injection channel.
class Injector {
 public:
  Injector() = default;
  // NOLINTNEXTLINE(google-explicit-constructor): a channel end is an injector that never routes in place
  Injector(csp::Out<Packet> out, Router* router = nullptr) : out_(std::move(out)), router_(router) {}
  void write(Packet packet) {
    if (router_ && router_->inject_in_place(packet)) return;
    out_.write(std::move(packet));
  }
  // Whether a write would not wait, as the injection channel last
  // published it: exact on the node's thread, where all its writers and
  // its router run.
  bool room_hint() const { return out_.room_hint(); }

 private:
  csp::Out<Packet> out_;
  Router* router_ = nullptr;
};

}  // namespace nodes
