// Network construction (channels, processes, placement), shutdown, and the
// aggregation and formatting of the per-process counters.
#include "nodes/net/network.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace nodes {
namespace {

std::string link_name(NodeId from, NodeId to, unsigned cls) {
  return "link " + std::to_string(from) + "->" + std::to_string(to) + " class " +
         std::to_string(cls);
}

}  // namespace

unsigned Network::block_placement(NodeId node, std::size_t nodes, unsigned threads) {
  return static_cast<unsigned>(std::uint64_t{node} * threads / std::max<std::size_t>(nodes, 1));
}

Network::Network(csp::Runtime& runtime, topology::Topology topology, NetworkOptions options)
    : topology_(std::move(topology)),
      options_(std::move(options)),
      classes_(topology_.buffer_classes()),
      threads_(runtime.threads()),
      routes_to_trace_(options_.trace_routes) {
  if (options_.buffer_capacity == 0) throw std::invalid_argument("network: buffer capacity must be at least 1");
  if (options_.ports_per_node == 0) throw std::invalid_argument("network: each node needs at least one local port");
  if (options_.local && options_.link.enabled())
    throw std::invalid_argument("network: a link model cannot carry links between processes");
  if (!options_.port_capacity.empty() && options_.link.enabled())
    throw std::invalid_argument("network: a link model delivers by rendezvous, so ports take no capacity");
  if (options_.relay_between_threads && options_.link.enabled())
    throw std::invalid_argument("network: a link model cannot be relayed between threads");
  for (const std::uint8_t kind : options_.trace_kinds) kinds_to_trace_[kind] = true;
  if (options_.relay_between_threads && threads_ > 1)
    relays_ = std::make_unique<ThreadRelays>(threads_, options_.buffer_capacity, options_.relay_wake);
  const std::size_t n = topology_.size();
  link_in_.resize(n);
  ports_.resize(n);
  injections_.resize(n);
  for (NodeId node = 0; node < n; ++node) {
    router_counters_.push_back(std::make_unique<RouterCounters>());
    if (!is_local(node)) continue;
    for (NodeId from : topology_.neighbours(node))
      for (unsigned c = 0; c < classes_; ++c) {
        link_in_[node].emplace_back(link_name(from, node, c), queue_capacity());
        if (!is_local(from)) cut_.incoming.emplace_back(CutLink{from, node, c}, link_in_[node].back().writer());
      }
    injections_[node] = csp::Channel<Packet>("inject " + std::to_string(node), options_.buffer_capacity);
    for (unsigned j = 0; j < options_.ports_per_node; ++j) {
      const std::size_t asked = j < options_.port_capacity.size() ? options_.port_capacity[j] : 0;
      ports_[node].emplace_back("port " + std::to_string(node) + "." + std::to_string(j),
                                asked > 0 ? std::max(asked, queue_capacity()) : queue_capacity());
    }
  }
  routers_.resize(n);
  for (NodeId node = 0; node < n; ++node)
    if (is_local(node)) wire_node(runtime, node);
  if (in_place()) forward_in_place();
  if (relays_) relays_->spawn(runtime);
}

unsigned Network::thread_of(NodeId node) const {
  return options_.placement ? options_.placement(node)
                            : block_placement(node, topology_.size(), threads_);
}

// Without a link model the channels into routers and ports are the routers'
// output queues; with one, each is a rendezvous fed by a link process.
std::size_t Network::queue_capacity() const { return options_.link.enabled() ? 0 : options_.buffer_capacity; }

// Link inputs of `node` are numbered by the port on `node` the link comes in
// by: output queue (port_to(node, m), c) of m feeds input
// port_to(node, m) * classes + c of node.
void Network::wire_node(csp::Runtime& runtime, NodeId node) {
  RouterEnds ends;
  for (const auto& ch : link_in_[node]) ends.inputs.push_back(ch.reader());
  ends.injections.push_back(injections_[node].reader());
  const auto neighbours = topology_.neighbours(node);
  for (topology::Port p = 0; p < neighbours.size(); ++p) {
    const NodeId m = neighbours[p];
    const std::size_t back = topology_.port_to(m, node);
    for (unsigned c = 0; c < classes_; ++c) {
      if (is_local(m) && relays_ && thread_of(m) != thread_of(node)) {
        cut_queues_.emplace_back("relayed " + link_name(node, m, c), options_.buffer_capacity);
        const std::size_t link = relays_->add(thread_of(node), thread_of(m), cut_queues_.back().reader(),
                                              link_in_[m][back * classes_ + c].writer());
        relayed_inputs_.push_back(RelayedInput{link, m, back * classes_ + c});
        relayed_outputs_.push_back(RelayedOutput{link, node, ends.outputs.size()});
        ends.outputs.push_back(cut_queues_.back().writer());
        continue;
      }
      if (is_local(m)) {
        ends.outputs.push_back(output_queue(runtime, node, link_in_[m][back * classes_ + c]));
        continue;
      }
      cut_queues_.emplace_back("cut " + link_name(node, m, c), options_.buffer_capacity);
      cut_.outgoing.emplace_back(CutLink{node, m, c}, cut_queues_.back().reader());
      ends.outputs.push_back(cut_queues_.back().writer());
    }
  }
  for (unsigned j = 0; j < options_.ports_per_node; ++j)
    ends.outputs.push_back(output_queue(runtime, node, ports_[node][j]));
  RouterConfig config{options_.trace_routes > 0 ? &routes_to_trace_ : nullptr,
                      options_.trace_kinds.empty() ? nullptr : &kinds_to_trace_, options_.recorder};
  auto router = std::make_shared<Router>(topology_, node, std::move(ends), config,
                                         *router_counters_[node]);
  routers_[node] = router;
  runtime.spawn("router " + std::to_string(node), thread_of(node), [router] { router->run(); });
}

// Every link queue between two routers of this process and thread, by the
// numbering of wire_node, every relayed link's delivery and, with
// send_across_in_place, every relayed link's sending.
void Network::forward_in_place() {
  for (const RelayedInput& r : relayed_inputs_) relays_->deliver_in_place(r.link, *routers_[r.node], r.input);
  if (options_.send_across_in_place)
    for (const RelayedOutput& r : relayed_outputs_) routers_[r.node]->send_across(r.queue, relays_->sender(r.link));
  for (NodeId node = 0; node < topology_.size(); ++node) {
    if (!is_local(node)) continue;
    const auto neighbours = topology_.neighbours(node);
    for (topology::Port p = 0; p < neighbours.size(); ++p) {
      const NodeId m = neighbours[p];
      if (!is_local(m) || thread_of(m) != thread_of(node)) continue;
      const std::size_t back = topology_.port_to(m, node);
      for (unsigned c = 0; c < classes_; ++c)
        routers_[node]->forward_in_place(p * classes_ + c, *routers_[m], back * classes_ + c);
    }
  }
}

// The channel a router of `node` writes to reach `next`: `next` itself, or
// with a link model a queue that a new link process carries into `next`.
csp::Out<Packet> Network::output_queue(csp::Runtime& runtime, NodeId node, const csp::Channel<Packet>& next) {
  if (!options_.link.enabled()) return next.writer();
  const std::string name = "wire into " + next.name();
  wires_.emplace_back(name, options_.buffer_capacity);
  auto link = std::make_shared<Link>(wires_.back().reader(), next.writer(), options_.link);
  runtime.spawn(name, thread_of(node), [link] { link->run(); });
  return wires_.back().writer();
}

csp::Out<Packet> Network::injector(NodeId node, unsigned port) const {
  if (port >= options_.ports_per_node)
    throw std::out_of_range("network: node " + std::to_string(node) + " has no port " + std::to_string(port));
  return injections_.at(node).writer();
}

Injector Network::in_place_injector(NodeId node, unsigned port) const {
  csp::Out<Packet> out = injector(node, port);
  return Injector(std::move(out), in_place() ? routers_.at(node).get() : nullptr);
}

csp::In<Packet> Network::port(NodeId node, unsigned port) const {
  return ports_.at(node).at(port).reader();
}

bool Network::receive_in_place(NodeId node, unsigned port, PortReceiver& receiver) {
  if (!in_place()) return false;
  if (!routers_.at(node))
    throw std::out_of_range("network: node " + std::to_string(node) + " runs in another process");
  routers_[node]->receive_in_place(port, receiver);  // which checks the port
  return true;
}

void Network::shutdown() {
  shut_down_.store(true, std::memory_order_release);
  if (relays_) relays_->poison();
  for (auto& ch : cut_queues_) ch.poison();
  for (auto& ch : injections_) ch.poison();
  for (auto& ch : wires_) ch.poison();
  for (auto& node : link_in_)
    for (auto& ch : node) ch.poison();
  for (auto& node : ports_)
    for (auto& ch : node) ch.poison();
}

NetworkStats Network::stats() const {
  std::vector<const RouterCounters*> routers;
  for (const auto& r : router_counters_) routers.push_back(r.get());
  return network_stats(topology_, routers);
}

NetworkStats network_stats(const topology::Topology& topology, const std::vector<const RouterCounters*>& routers) {
  const unsigned classes = topology.buffer_classes();
  NetworkStats s;
  for (NodeId node = 0; node < topology.size(); ++node) {
    const RouterCounters& r = *routers.at(node);
    s.routers.push_back(r);
    s.hops.merge(r.hops);
    for (std::size_t kind = 0; kind < r.hops_by_kind.size(); ++kind)
      if (r.hops_by_kind[kind].packets) s.hops_by_kind[static_cast<std::uint8_t>(kind)].merge(r.hops_by_kind[kind]);
    s.routes.insert(s.routes.end(), r.routes.begin(), r.routes.end());
    // Link queues come first, classes_ per port, in port order.
    const auto neighbours = topology.neighbours(node);
    for (topology::Port p = 0; p < neighbours.size(); ++p) {
      LinkStats link{node, neighbours[p], 0, 0};
      for (unsigned c = 0; c < classes && p * classes + c < r.sent.size(); ++c) {
        const LinkCounters& lc = r.sent[p * classes + c];
        link.packets += lc.packets;
        link.bytes += lc.bytes;
      }
      s.links.push_back(link);
    }
  }
  std::sort(s.routes.begin(), s.routes.end(),
            [](const RouteRecord& a, const RouteRecord& b) { return a.id < b.id; });
  return s;
}

std::string format_route(const RouteRecord& record, const KindNamer& kind_name) {
  std::string s = kind_name(record.kind) + " " + std::to_string(record.id) + ":";
  for (std::size_t i = 0; i < record.route.size(); ++i)
    s += (i ? " \u2192 " : " ") + std::to_string(record.route[i]);
  const std::size_t hops = record.route.empty() ? 0 : record.route.size() - 1;
  s += " (" + std::to_string(hops) + (hops == 1 ? " hop)" : " hops)");
  return s;
}

const LinkStats* busiest_link(const NetworkStats& stats) {
  const auto busiest = std::max_element(stats.links.begin(), stats.links.end(),
                                        [](const LinkStats& a, const LinkStats& b) { return a.packets < b.packets; });
  return busiest == stats.links.end() ? nullptr : &*busiest;
}

std::string format_summary(const NetworkStats& stats, const topology::Topology& topology,
                           const KindNamer& kind_name) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << "network " << topology.spec() << ": " << stats.hops.packets << " packets delivered, "
      << "mean hops " << stats.hops.mean() << " (max " << stats.hops.max_hops
      << "), analytic average distance " << topology.average_distance() << "\n";
  out << "  " << std::left << std::setw(16) << "kind" << std::right << std::setw(12) << "packets"
      << std::setw(12) << "mean hops" << std::setw(10) << "max" << "\n";
  for (const auto& [kind, h] : stats.hops_by_kind)
    out << "  " << std::left << std::setw(16) << kind_name(kind) << std::right << std::setw(12)
        << h.packets << std::setw(12) << h.mean() << std::setw(10) << h.max_hops << "\n";
  if (const LinkStats* busiest = busiest_link(stats))
    out << "  busiest link (most packets) " << busiest->from << " -> " << busiest->to << ": " << busiest->packets
        << " packets, " << busiest->bytes << " bytes\n";
  std::uint32_t peak = 0;
  std::uint64_t forwarded = 0, in_place = 0;
  for (const auto& r : stats.routers) {
    peak = std::max(peak, r.peak_pending);
    forwarded += r.forwarded;
    in_place += r.in_place;
  }
  out << "  packets forwarded by routers " << forwarded
      << ", most packets held back by one router (its output queues full) " << peak << "\n";
  if (in_place)
    out << "  router steps taken in place, by the sender on the router's thread " << in_place << "\n";
  return out.str();
}

}  // namespace nodes
