// Latency against offered load: every node injects packets of a traffic
// pattern at a steady rate into a network with a link model, in virtual
// time, and the packets created in a measurement window are timed from
// creation (their wait at the source included, as an infinite source queue
// would hold them) to delivery. One runtime thread, so a run is
// deterministic: the same options give the same numbers.
//
// Besides the synthetic patterns, a recorded one: packets with their
// sources, destinations and sizes, which each source offers in its order
// (the layer above records them from a render). Invariants: every packet created is delivered exactly once to its
// destination (counted, never assumed); the run ends when the last packet
// created is delivered, however far past saturation the load is. Knows
// nothing of the command line (app/experiments/network_study.hpp drives it).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "nodes/net/link.hpp"
#include "nodes/net/network.hpp"
#include "topology/topology.hpp"

namespace nodes {

// Traffic patterns on node ids as digits (the hypercube's bits, the mesh's
// and torus's coordinates, the ring's and complete graph's index).
// `recorded` ("render") offers LoadStudyOptions::recorded.
enum class TrafficPattern {
  uniform, transpose, bit_complement, bit_reversal, shuffle, tornado, neighbour, hotspot, recorded
};

// Recorded traffic: per source node, its packets in the order it sent them.
struct RecordedPacket {
  topology::NodeId destination = 0;
  std::uint32_t bytes = 0;  // payload
};
struct RecordedTraffic {
  std::vector<std::vector<RecordedPacket>> by_source;  // index = node
  std::uint64_t packets() const;
};

// Every pattern, in the order --help lists them.
const std::vector<TrafficPattern>& traffic_patterns();
const char* pattern_name(TrafficPattern pattern);
// std::invalid_argument naming the pattern and the known ones.
TrafficPattern parse_traffic_pattern(const std::string& name);
// One line per pattern, for --help.
std::string pattern_descriptions();
// Why `pattern` is not defined on `t` ("transpose needs a square ..."), or
// "" when it is.
std::string pattern_unfit(TrafficPattern pattern, const topology::Topology& t);

// Fixed destinations of a deterministic pattern, one per node (a node whose
// destination is itself sends nothing); empty for uniform and hotspot.
std::vector<topology::NodeId> fixed_destinations(TrafficPattern pattern, const topology::Topology& t);

struct LoadStudyOptions {
  LinkModel link;                       // per hop (and per delivery): latency and bandwidth
  std::size_t payload_bytes = 64;       // bytes a packet carries
  std::size_t buffer_capacity = 4;      // packets per output queue
  double hotspot_fraction = 0.2;        // hotspot: share of packets sent to node 0, the rest uniform
  double warmup_seconds = 0;            // virtual time before the window (0: 20 zero-load latencies)
  double window_seconds = 0;            // the measurement window (0: 200 zero-load latencies)
  std::uint32_t seed = 1;
  // The recorded pattern's packets, for a topology of by_source.size()
  // nodes: each source sends its own in order, cycling, at its share of the
  // load (so the nodes' mean is the offered load), each packet its size.
  std::shared_ptr<const RecordedTraffic> recorded;
};

// The channel load of the busiest link when every node offers one packet
// per second (uniform: spread over all other nodes; hotspot: its share to
// node 0), under the network's deterministic routing, the delivery channel
// into each node counted as a link too. A network saturates where the
// offered load per node reaches link capacity / this.
double max_channel_load(const topology::Topology& t, TrafficPattern pattern, double hotspot_fraction);
// The same for recorded traffic, its sizes counted: the busiest link's busy
// time, in message times of `payload_bytes`, when the nodes offer one packet
// per second on average, each at its share; and its zero-load latency, the
// mean over its packets. std::invalid_argument when the recording's node
// count is not t's or it holds a packet to its own source or beyond t.
double recorded_channel_load(const topology::Topology& t, const RecordedTraffic& traffic, const LinkModel& link,
                             std::size_t payload_bytes);
double recorded_zero_load_latency(const topology::Topology& t, const RecordedTraffic& traffic, const LinkModel& link);

// One point of a curve.
struct LoadResult {
  double offered = 0;      // packets per node per second offered
  double accepted = 0;     // packets per node per second delivered in the window
  std::uint64_t created = 0, delivered = 0, misdelivered = 0;  // over the whole run
  std::uint64_t measured = 0;  // packets created in the window, each timed
  double mean_latency = 0, p50_latency = 0, p99_latency = 0, max_latency = 0;  // seconds, of the measured
  double mean_hops = 0;    // links crossed by the measured, delivery not counted
  double mean_in_flight = 0;  // packets created and not yet delivered, averaged over the window
  double arrival_rate = 0;    // packets created per second in the window, whole network (Little's law's λ)
  double end_seconds = 0;     // virtual time when the last packet was delivered
  std::vector<LinkStats> links;  // what each directed link carried over the whole run
};

// Zero-load latency of a packet over `distance` links: store and forward,
// each link and the delivery one message time.
double zero_load_latency(const LinkModel& link, std::size_t payload_bytes, unsigned distance);

// Runs one load point: `offered` packets per node per second, exponential
// gaps (seeded), until every packet created before the window's end is
// delivered. std::invalid_argument for a pattern the topology does not fit,
// a link model without latency or bandwidth, or an offered load <= 0.
LoadResult run_load(const topology::Topology& t, TrafficPattern pattern, double offered,
                    const LoadStudyOptions& options);

}  // namespace nodes
