// nodes::Network: the store-and-forward interconnect of the simulated machine,
// built on a csp::Runtime along a topology::Topology (docs/architecture.md,
// "One processor" and "Why the network cannot deadlock", draws it).
//
// Per node: a Router (router.hpp) whose output queues are channels of
// buffer_capacity packets, one per outgoing link and buffer class and one per
// local port (port(n, p)); local processes write into one shared injection
// channel (injector(n)). With a link model, a Link process per output queue
// (link.hpp); with relay_between_threads, links between threads go through
// the threads' relays (thread_relay.hpp); split over ranks, only the local
// nodes exist and cut links end at the rank's bridge (bridge.hpp).
// Invariants: every buffer is bounded; deadlock freedom rests on the acyclic
// channel dependencies of topology::next_hop and the consumption assumption
// of router.hpp. shutdown() poisons every network channel (packets still in
// flight are dropped), so run() returns with no fiber blocked.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/link.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/net/router.hpp"
#include "nodes/net/thread_relay.hpp"
#include "topology/topology.hpp"

namespace nodes {

struct NetworkOptions {
  std::size_t buffer_capacity = 4;  // packets per output queue and per injection channel, at least 1
  unsigned ports_per_node = 1;      // local ports per node
  std::uint64_t trace_routes = 0;   // record the routes of the first this many packets injected
  std::vector<std::uint8_t> trace_kinds;  // of these kinds only (empty: every kind)
  RouteRecorder* recorder = nullptr;      // every router records its hops here (route_log.hpp); null: none
  LinkModel link;                   // optional per-hop latency and bandwidth
  // Delivery queues larger than buffer_capacity, by local port (0 or no
  // entry: buffer_capacity): a receiver whose outstanding packets the
  // protocol bounds can read its port directly, the queue holding them all,
  // instead of through a mailbox (mailbox.hpp). Without a link model only:
  // with one, delivery is a rendezvous.
  std::vector<std::size_t> port_capacity;
  std::function<unsigned(NodeId)> placement;  // thread of node n; default block
  std::function<bool(NodeId)> local;          // nodes this process runs; default all
  // Links between routers on different threads go through the threads'
  // relays (thread_relay.hpp) instead of channels shared by two threads.
  // Real time only (the relays need FifoScheduler); not with a link model.
  bool relay_between_threads = false;
  // Routers route their same-thread neighbours' packets in place when the
  // neighbour could take them at once, and in_place_injector() routes a
  // local process's packet so (router.hpp). Without a link model only.
  bool forward_in_place = false;
  // With both of the above: a router's step puts a packet for a link to
  // another thread straight into the relays' ring and tells that thread
  // (ThreadRelays::sender) when the link's queue is empty and credits are
  // left, instead of waking its thread's relay to move it.
  bool send_across_in_place = false;
  // How the relays tell a thread of entries in its rings (RelayWake): its
  // scheduler polls them, or each batch signals it.
  RelayWake relay_wake = RelayWake::poll;
};

// One direction and buffer class of a link whose ends run in different processes.
struct CutLink {
  NodeId from = 0;
  NodeId to = 0;
  unsigned buffer_class = 0;
};

struct CutEnds {
  std::vector<std::pair<CutLink, csp::In<Packet>>> outgoing;   // local `from`: its router's output queue
  std::vector<std::pair<CutLink, csp::Out<Packet>>> incoming;  // local `to`: into its router
};

struct LinkStats {
  NodeId from = 0;
  NodeId to = 0;
  std::uint64_t packets = 0;
  std::uint64_t bytes = 0;
};

struct NetworkStats {
  std::vector<RouterCounters> routers;  // index = node
  std::vector<LinkStats> links;         // one per directed link, classes summed
  HopSummary hops;                      // of all delivered packets
  std::map<std::uint8_t, HopSummary> hops_by_kind;
  std::vector<RouteRecord> routes;  // traced packets, by id
};

using KindNamer = std::function<std::string(std::uint8_t kind)>;

class Network {
 public:
  Network(csp::Runtime& runtime, topology::Topology topology, NetworkOptions options = {});
  Network(const Network&) = delete;
  Network& operator=(const Network&) = delete;

  const topology::Topology& topology() const { return topology_; }
  const NetworkOptions& options() const { return options_; }

  csp::Out<Packet> injector(NodeId node, unsigned port = 0) const;
  Injector in_place_injector(NodeId node, unsigned port = 0) const;
  csp::In<Packet> port(NodeId node, unsigned port = 0) const;
  // Before the run, when routers route in place (forward_in_place, no link
  // model): `receiver`, a process on the node's thread that reads `port`,
  // takes deliveries there in place when it can (Router::receive_in_place).
  // False, nothing registered, otherwise.
  bool receive_in_place(NodeId node, unsigned port, PortReceiver& receiver);
  unsigned thread_of(NodeId node) const;

  bool is_local(NodeId node) const { return !options_.local || options_.local(node); }
  // The links to and from other processes (empty unless `local` is set).
  const CutEnds& cut_ends() const { return cut_; }

  // Safe from any thread, more than once; after it, shut_down() is true.
  void shutdown();
  bool shut_down() const { return shut_down_.load(std::memory_order_acquire); }
  NetworkStats stats() const;  // after Runtime::run() has returned
  // Counters of one router (zero for a node this process does not run).
  const RouterCounters& router_counters(NodeId node) const { return *router_counters_.at(node); }

  // Links carried by thread relays (0 without them), and what each
  // thread's relay carried (after run()).
  std::size_t relayed_links() const { return relays_ ? relays_->links() : 0; }
  RelayCounters relay_counters(unsigned thread) const {
    return relays_ ? relays_->counters(thread) : RelayCounters{};
  }

  // Contiguous ranges of nodes per thread: node * threads / nodes.
  static unsigned block_placement(NodeId node, std::size_t nodes, unsigned threads);

 private:
  void wire_node(csp::Runtime& runtime, NodeId node);
  void forward_in_place();
  bool in_place() const { return options_.forward_in_place && !options_.link.enabled(); }
  csp::Out<Packet> output_queue(csp::Runtime& runtime, NodeId node, const csp::Channel<Packet>& next);
  std::size_t queue_capacity() const;

  topology::Topology topology_;
  NetworkOptions options_;
  unsigned classes_;
  unsigned threads_;
  // Per node, per (port, class): the channel into that node's router.
  std::vector<std::vector<csp::Channel<Packet>>> link_in_;
  std::vector<csp::Channel<Packet>> injections_;  // per node
  std::vector<std::vector<csp::Channel<Packet>>> ports_;
  std::vector<csp::Channel<Packet>> wires_;  // link model only: router -> link process
  std::vector<csp::Channel<Packet>> cut_queues_;  // local router -> bridge (toward remote nodes) or relay (other thread)
  CutEnds cut_;
  std::unique_ptr<ThreadRelays> relays_;  // with relay_between_threads and several threads
  std::atomic<bool> shut_down_{false};
  // Counters live here so they outlive the processes; each is written by
  // exactly one process and read only after run().
  std::vector<std::unique_ptr<RouterCounters>> router_counters_;
  std::vector<std::shared_ptr<Router>> routers_;  // per node; null for a node of another process
  struct RelayedInput {
    std::size_t link;   // the relays' link
    NodeId node;        // whose router it feeds
    std::size_t input;  // by that router's input
  };
  std::vector<RelayedInput> relayed_inputs_;
  struct RelayedOutput {
    std::size_t link;   // the relays' link
    NodeId node;        // whose router sends on it
    std::size_t queue;  // by that router's output queue
  };
  std::vector<RelayedOutput> relayed_outputs_;
  std::atomic<std::uint64_t> routes_to_trace_;  // RouterConfig::routes_to_trace
  std::array<bool, 256> kinds_to_trace_{};      // RouterConfig::kinds_to_trace, from trace_kinds
};

// The network's figures from every router's counters (index = node).
NetworkStats network_stats(const topology::Topology& topology, const std::vector<const RouterCounters*>& routers);

// "page 17: 5 → 4 → 6 → 7 (3 hops)"
std::string format_route(const RouteRecord& record, const KindNamer& kind_name);

// The link that carried the most packets, or null for a machine without links.
const LinkStats* busiest_link(const NetworkStats& stats);

// Table: packets, mean/max hops overall and per kind, busiest link, peak buffers.
std::string format_summary(const NetworkStats& stats, const topology::Topology& topology,
                           const KindNamer& kind_name);

}  // namespace nodes
