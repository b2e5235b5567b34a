// nodes::Recorder: what a run did over time, for a replay of it: every hop of
// the first packets injected, the page requests each pixel computer waited
// on, the pages each page server served, and (from the tile spans) what each
// pixel computer traced when.
//
// One NodeLog per node, written only by that node's processes (its router
// through the RouteLog it extends, net/route_log.hpp, its page server and
// pixel computers, all on the node's thread): no lock. The first max_packets
// packets injected are recorded hop by hop, later ones only counted per kind.
// Invariants of a merged Recording (merge_recording checks them and throws
// std::logic_error otherwise): each packet's route runs from its source to
// its destination through neighbours, its times never decrease, and packets
// recorded and counted together are every packet delivered. What is recorded
// and what it costs: docs/architecture.md, "The recorder and the replay".
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "nodes/machine/node_observer.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/net/route_log.hpp"
#include "topology/topology.hpp"

namespace nodes {

// A pixel computer waiting for a page it asked for, from request to reply.
struct FetchEvent {
  double start = 0;
  double end = 0;
  std::uint32_t page = 0;
  std::uint16_t worker = 0;
};

// A page server serving one request, from reading it to sending the reply.
struct ServeEvent {
  double start = 0;
  double end = 0;
  std::uint32_t page = 0;
  NodeId to = 0;
};

// What a pixel computer's page calls found at hand so far (own pages and
// cache hits), after each tile: the cache over time.
struct HitSample {
  double time = 0;
  std::uint64_t hits = 0;  // since the run began
  std::uint16_t worker = 0;
};

// A node's log: its router's (route_log.hpp), then its own processes'.
struct NodeLog : RouteLog {
  std::vector<FetchEvent> fetches;
  std::vector<ServeEvent> serves;
  std::vector<HitSample> hits;
  std::uint64_t unrecorded_fetches = 0;  // begun after the budget was spent
  std::uint64_t unrecorded_serves = 0;
};

class Recorder final : public RouteRecorder {
 public:
  Recorder(std::size_t nodes, std::uint64_t max_packets, bool virtual_time,
           std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now());

  NodeLog& log(NodeId node) { return *logs_.at(node); }
  const NodeLog& log(NodeId node) const { return *logs_.at(node); }
  RouteLog& route_log(NodeId node) override { return log(node); }
  std::size_t nodes() const { return logs_.size(); }
  // Replaces a node's log with one another rank recorded, its times already
  // moved onto this recorder's clock (shift_times).
  void adopt(NodeId node, NodeLog log) { *logs_.at(node) = std::move(log); }

 private:
  std::vector<std::unique_ptr<NodeLog>> logs_;
};

// The recorder's observer of one node's pixel computers: each wait for a
// page logged while the budget lasts (Recorder::open() as the request
// leaves), only counted after; and after each tile, what the worker's page
// calls have found at hand so far (a HitSample).
class RecordingObserver final : public NodeObserver {
 public:
  RecordingObserver(Recorder& recorder, NodeId node, int workers);
  void fetch_started(int worker, std::uint32_t page) override;
  void fetch_ended(int worker, std::uint32_t page) override;
  void tile_done(int worker, const SvmStats& memory) override;

 private:
  Recorder& recorder_;
  NodeId node_;
  std::vector<std::optional<double>> waiting_;  // per worker: when its recorded wait began; none: not recorded
};

// One recorded packet, merged from the logs of the nodes it crossed.
struct PacketTrace {
  std::uint64_t id = 0;
  std::uint8_t kind = 0;
  std::uint32_t bytes = 0;
  std::vector<NodeId> route;  // source first, destination last: hops + 1 nodes
  // injected, then per hop its departure and arrival, then delivered:
  // 2 * route.size() times.
  std::vector<double> times;

  std::size_t hops() const { return route.size() - 1; }
  double injected() const { return times.front(); }
  double delivered() const { return times.back(); }
  double departs(std::size_t hop) const { return times[1 + 2 * hop]; }
  double arrives(std::size_t hop) const { return times[2 + 2 * hop]; }
};

struct NodeTrace {
  std::vector<FetchEvent> fetches;  // in the order each worker made them
  std::vector<ServeEvent> serves;   // in order
  std::vector<HitSample> hits;      // in the order each worker took them
  std::vector<TileSpan> tiles;      // as the machine recorded them (record_tiles)
  std::uint64_t unrecorded_fetches = 0, unrecorded_serves = 0;  // only counted: begun after the budget was spent
};

struct Recording {
  std::vector<int> node_rank;  // the rank that ran each node; empty when one process ran them all
  bool virtual_time = false;
  std::uint64_t max_packets = 0;
  std::vector<PacketTrace> packets;             // by injection time, then id
  std::vector<NodeTrace> nodes;                 // index = node
  std::array<std::uint64_t, 256> unrecorded{};  // packets delivered but not recorded, by kind
  std::uint64_t unrecorded_packets = 0;
  std::uint64_t unrecorded_hops = 0;
  std::uint64_t unrecorded_fetches = 0;  // waits for pages begun after the budget was spent
  std::uint64_t unrecorded_serves = 0;
  double end = 0;     // the latest time recorded
  double window = 0;  // the latest start of a recorded packet, wait or serve: end if nothing went unrecorded

  std::uint64_t recorded_hops() const;
};

// Moves every time in the log by `seconds`: another rank's clock onto rank 0's.
void shift_times(NodeLog& log, double seconds);

// The logs joined packet by packet, with each node's tiles (index = node).
// With `node_rank` (a run over several ranks, each node's log on its rank's
// clock moved onto rank 0's), a packet's times after a hop between ranks
// are raised to at least the time before it, so that what is left of the
// clocks' difference never shows a packet arriving before it left; the
// window is then the earliest of the ranks' own windows.
Recording merge_recording(const Recorder& recorder, const topology::Topology& topology,
                          std::vector<std::vector<TileSpan>> tiles, std::vector<int> node_rank = {});

}  // namespace nodes
