// The recorder's clock and budget, and the merge of its per-node logs into
// one trace per packet (see recorder.hpp).
#include "nodes/machine/recorder.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace nodes {

Recorder::Recorder(std::size_t nodes, std::uint64_t max_packets, bool virtual_time,
                   std::chrono::steady_clock::time_point started)
    : RouteRecorder(max_packets, virtual_time, started) {
  for (std::size_t n = 0; n < nodes; ++n) logs_.push_back(std::make_unique<NodeLog>());
}

RecordingObserver::RecordingObserver(Recorder& recorder, NodeId node, int workers)
    : recorder_(recorder), node_(node), waiting_(static_cast<std::size_t>(workers)) {}

void RecordingObserver::fetch_started(int worker, std::uint32_t /*page*/) {
  std::optional<double>& waiting = waiting_.at(static_cast<std::size_t>(worker));
  waiting.reset();
  if (recorder_.open())
    waiting = recorder_.now();
  else
    ++recorder_.log(node_).unrecorded_fetches;
}

void RecordingObserver::fetch_ended(int worker, std::uint32_t page) {
  std::optional<double>& waiting = waiting_.at(static_cast<std::size_t>(worker));
  if (!waiting) return;
  recorder_.log(node_).fetches.push_back({*waiting, recorder_.now(), page, static_cast<std::uint16_t>(worker)});
  waiting.reset();
}

void RecordingObserver::tile_done(int worker, const SvmStats& memory) {
  recorder_.log(node_).hits.push_back(
      {recorder_.now(), memory.own_hits + memory.cache_hits, static_cast<std::uint16_t>(worker)});
}

std::uint64_t Recording::recorded_hops() const {
  std::uint64_t hops = 0;
  for (const PacketTrace& p : packets) hops += p.hops();
  return hops;
}

namespace {

constexpr double unset = -std::numeric_limits<double>::infinity();
constexpr NodeId no_node = std::numeric_limits<NodeId>::max();

[[noreturn]] void broken(std::uint64_t id, const std::string& what) {
  throw std::logic_error("recording: packet " + std::to_string(id) + " " + what);
}

PacketTrace& trace_of(const std::unordered_map<std::uint64_t, std::size_t>& index, std::vector<PacketTrace>& packets,
                      std::uint64_t id) {
  const auto at = index.find(id);
  if (at == index.end()) broken(id, "was seen in the network but never injected");
  return packets[at->second];
}

void set(PacketTrace& p, std::size_t slot, double time) {
  if (slot >= p.times.size()) broken(p.id, "crossed more links than it was delivered with");
  if (p.times[slot] != unset) broken(p.id, "was recorded twice at one step");
  p.times[slot] = time;
}

void check(const PacketTrace& p, const topology::Topology& topology, NodeId destination) {
  for (std::size_t i = 0; i < p.route.size(); ++i)
    if (p.route[i] == no_node) broken(p.id, "has a hop nobody recorded");
  if (p.route.back() != destination) broken(p.id, "ended away from its destination");
  for (std::size_t h = 0; h < p.hops(); ++h) {
    const auto next = topology.neighbours(p.route[h]);
    if (std::find(next.begin(), next.end(), p.route[h + 1]) == next.end())
      broken(p.id, "went from " + std::to_string(p.route[h]) + " to " + std::to_string(p.route[h + 1]) +
                       ", which are not neighbours");
  }
  for (std::size_t i = 0; i < p.times.size(); ++i) {
    if (p.times[i] == unset) broken(p.id, "misses a time");
    if (i > 0 && p.times[i] < p.times[i - 1]) broken(p.id, "arrived before it left");
  }
}

}  // namespace

namespace {

// Every packet injected, with its first node and time; `index` finds a
// packet's trace by id, `destination` holds where each was sent.
void add_injections(const Recorder& recorder, Recording& r, std::unordered_map<std::uint64_t, std::size_t>& index,
                    std::vector<NodeId>& destination) {
  for (NodeId n = 0; n < recorder.nodes(); ++n)
    for (const InjectEvent& e : recorder.log(n).injected) {
      if (!index.emplace(e.id, r.packets.size()).second) broken(e.id, "was injected twice");
      PacketTrace p;
      p.id = e.id;
      p.kind = e.kind;
      p.bytes = e.bytes;
      p.route = {n};
      p.times = {e.time};
      r.packets.push_back(std::move(p));
      destination.push_back(e.destination);
    }
}

// A packet's length is known where it is delivered: size every trace then.
void add_deliveries(const Recorder& recorder, Recording& r,
                    const std::unordered_map<std::uint64_t, std::size_t>& index) {
  for (NodeId n = 0; n < recorder.nodes(); ++n)
    for (const DeliverEvent& e : recorder.log(n).delivered) {
      PacketTrace& p = trace_of(index, r.packets, e.id);
      if (p.times.size() != 1) broken(e.id, "was delivered twice");
      const NodeId source = p.route.front();
      const double injected = p.times.front();
      p.route.assign(e.hops + 1u, no_node);
      p.route.front() = source;
      p.route.back() = n;
      p.times.assign(2 * (e.hops + 1u), unset);
      p.times.front() = injected;
      p.times.back() = e.time;
    }
}

// Every hop's departure and arrival into its trace, and what each node
// counted without recording.
void add_hops(const Recorder& recorder, const topology::Topology& topology, Recording& r,
              const std::unordered_map<std::uint64_t, std::size_t>& index) {
  const unsigned classes = topology.buffer_classes();
  for (NodeId n = 0; n < recorder.nodes(); ++n) {
    const NodeLog& log = recorder.log(n);
    const auto neighbours = topology.neighbours(n);
    for (const HopEvent& e : log.departed) {
      PacketTrace& p = trace_of(index, r.packets, e.id);
      if (e.hop >= p.route.size() - 1) broken(e.id, "left a node after its last hop");
      if (p.route[e.hop] != n && p.route[e.hop] != no_node) broken(e.id, "left from two nodes at one hop");
      p.route[e.hop] = n;
      const std::size_t port = e.queue / classes;
      if (port >= neighbours.size()) broken(e.id, "left node " + std::to_string(n) + " by a port it lacks");
      if (p.route[e.hop + 1u] != no_node && p.route[e.hop + 1u] != neighbours[port])
        broken(e.id, "arrived elsewhere than it left for");
      p.route[e.hop + 1u] = neighbours[port];
      set(p, 1 + 2 * std::size_t{e.hop}, e.time);
    }
    for (const HopEvent& e : log.arrived) {
      PacketTrace& p = trace_of(index, r.packets, e.id);
      if (e.hop == 0 || e.hop >= p.route.size()) broken(e.id, "arrived at a hop it never made");
      if (p.route[e.hop] != n && p.route[e.hop] != no_node) broken(e.id, "arrived elsewhere than it left for");
      p.route[e.hop] = n;
      set(p, 2 * std::size_t{e.hop}, e.time);
    }
    for (std::size_t kind = 0; kind < log.unrecorded.size(); ++kind) {
      r.unrecorded[kind] += log.unrecorded[kind];
      r.unrecorded_packets += log.unrecorded[kind];
    }
    r.unrecorded_hops += log.unrecorded_hops;
    r.unrecorded_fetches += log.unrecorded_fetches;
    r.unrecorded_serves += log.unrecorded_serves;
  }
}

// Each node's waits, serves, hits and tiles, and the recording's end.
void add_node_traces(const Recorder& recorder, Recording& r, std::vector<std::vector<TileSpan>>& tiles) {
  r.nodes.resize(recorder.nodes());
  for (NodeId n = 0; n < recorder.nodes(); ++n) {
    NodeTrace& t = r.nodes[n];
    t.fetches = recorder.log(n).fetches;
    t.serves = recorder.log(n).serves;
    t.hits = recorder.log(n).hits;
    t.tiles = std::move(tiles[n]);
    t.unrecorded_fetches = recorder.log(n).unrecorded_fetches;
    t.unrecorded_serves = recorder.log(n).unrecorded_serves;
    for (const FetchEvent& e : t.fetches) r.end = std::max(r.end, e.end);
    for (const ServeEvent& e : t.serves) r.end = std::max(r.end, e.end);
    for (const TileSpan& s : t.tiles) r.end = std::max(r.end, s.end);
  }
}

// What was recorded in full: the whole run, or up to the last packet,
// wait or serve begun before the budget ran out. Over several ranks each
// spent a budget of its own: up to the earliest of their last starts.
double recorded_window(const Recording& r) {
  if (r.unrecorded_packets + r.unrecorded_fetches + r.unrecorded_serves == 0) return r.end;
  const auto rank_of = [&r](NodeId n) { return r.node_rank.empty() ? 0 : r.node_rank[n]; };
  std::vector<double> last(r.node_rank.empty() ? 1 : *std::max_element(r.node_rank.begin(), r.node_rank.end()) + 1,
                           0.0);
  for (const PacketTrace& p : r.packets) {
    double& at = last[static_cast<std::size_t>(rank_of(p.route.front()))];
    at = std::max(at, p.injected());
  }
  for (NodeId n = 0; n < r.nodes.size(); ++n) {
    double& at = last[static_cast<std::size_t>(rank_of(n))];
    for (const FetchEvent& e : r.nodes[n].fetches) at = std::max(at, e.start);
    for (const ServeEvent& e : r.nodes[n].serves) at = std::max(at, e.start);
  }
  return *std::min_element(last.begin(), last.end());
}

// After the first hop between ranks, each time at least the one before.
void raise_times_across_ranks(PacketTrace& p, const std::vector<int>& node_rank) {
  for (std::size_t h = 0; h < p.hops(); ++h) {
    if (p.route[h] >= node_rank.size() || p.route[h + 1] >= node_rank.size()) return;  // check() says why
    if (node_rank[p.route[h]] == node_rank[p.route[h + 1]]) continue;
    for (std::size_t i = 2 + 2 * h; i < p.times.size(); ++i) p.times[i] = std::max(p.times[i], p.times[i - 1]);
    return;
  }
}

}  // namespace

void shift_times(NodeLog& log, double seconds) {
  for (InjectEvent& e : log.injected) e.time += seconds;
  for (HopEvent& e : log.departed) e.time += seconds;
  for (HopEvent& e : log.arrived) e.time += seconds;
  for (DeliverEvent& e : log.delivered) e.time += seconds;
  for (FetchEvent& e : log.fetches) e.start += seconds, e.end += seconds;
  for (ServeEvent& e : log.serves) e.start += seconds, e.end += seconds;
  for (HitSample& e : log.hits) e.time += seconds;
}

Recording merge_recording(const Recorder& recorder, const topology::Topology& topology,
                          std::vector<std::vector<TileSpan>> tiles, std::vector<int> node_rank) {
  const std::size_t nodes = recorder.nodes();
  if (topology.size() != nodes)
    throw std::invalid_argument("recording: " + std::to_string(nodes) + " node logs for a machine of " +
                                std::to_string(topology.size()));
  if (!node_rank.empty() && node_rank.size() != nodes)
    throw std::invalid_argument("recording: the ranks of " + std::to_string(node_rank.size()) +
                                " nodes for a machine of " + std::to_string(nodes));
  tiles.resize(nodes);
  Recording r;
  r.node_rank = std::move(node_rank);
  r.virtual_time = recorder.virtual_time();
  r.max_packets = recorder.max_packets();
  std::unordered_map<std::uint64_t, std::size_t> index;
  std::vector<NodeId> destination;
  add_injections(recorder, r, index, destination);
  add_deliveries(recorder, r, index);
  add_hops(recorder, topology, r, index);
  for (std::size_t i = 0; i < r.packets.size(); ++i) {
    if (r.packets[i].times.size() != 2 * r.packets[i].route.size()) broken(r.packets[i].id, "was never delivered");
    if (!r.node_rank.empty()) raise_times_across_ranks(r.packets[i], r.node_rank);
    check(r.packets[i], topology, destination[i]);
    r.end = std::max(r.end, r.packets[i].delivered());
  }
  std::sort(r.packets.begin(), r.packets.end(), [](const PacketTrace& a, const PacketTrace& b) {
    return std::tie(a.times.front(), a.id) < std::tie(b.times.front(), b.id);
  });
  add_node_traces(recorder, r, tiles);
  r.window = recorded_window(r);
  return r;
}

}  // namespace nodes
