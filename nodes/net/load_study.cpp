// The load study's patterns, channel loads and its virtual-time run (see
// load_study.hpp).
#include "nodes/net/load_study.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>

#include "csp/csp.hpp"
#include "csp/virtual_time.hpp"
#include "nodes/net/network.hpp"

namespace nodes {
namespace {

using topology::Kind;
using topology::NodeId;
using topology::Topology;

// A node id as digits, lowest first, with each digit's radix: the
// hypercube's bits, the grid's x then y, the ring's or complete graph's index.
std::vector<unsigned> radices(const Topology& t) {
  switch (t.kind()) {
    case Kind::hypercube: return std::vector<unsigned>(t.dimension(), 2);
    case Kind::mesh:
    case Kind::torus: return {t.width(), t.height()};
    case Kind::ring:
    case Kind::complete: break;
  }
  return {static_cast<unsigned>(t.size())};
}

NodeId each_digit(const Topology& t, NodeId n, unsigned (*f)(unsigned digit, unsigned radix)) {
  NodeId result = 0, scale = 1;
  for (const unsigned k : radices(t)) {
    result += scale * f(n % k, k);
    n /= k;
    scale *= k;
  }
  return result;
}

bool power_of_two(const Topology& t) { return std::has_single_bit(t.size()); }
unsigned bits(const Topology& t) { return static_cast<unsigned>(std::countr_zero(t.size())); }
unsigned square_side(const Topology& t) {
  const auto m = static_cast<unsigned>(std::lround(std::sqrt(static_cast<double>(t.size()))));
  return static_cast<std::size_t>(m) * m == t.size() ? m : 0;
}

NodeId fixed_destination(TrafficPattern pattern, const Topology& t, NodeId n) {
  const NodeId mask = static_cast<NodeId>(t.size() - 1);
  switch (pattern) {
    case TrafficPattern::bit_complement: return ~n & mask;
    case TrafficPattern::bit_reversal: {
      NodeId r = 0;
      for (unsigned i = 0; i < bits(t); ++i) r |= ((n >> i) & 1u) << (bits(t) - 1 - i);
      return r;
    }
    case TrafficPattern::shuffle: return bits(t) == 0 ? n : ((n << 1) | (n >> (bits(t) - 1))) & mask;
    case TrafficPattern::transpose: {
      const unsigned m = square_side(t);
      return (n % m) * m + n / m;
    }
    case TrafficPattern::tornado:
      return each_digit(t, n, [](unsigned d, unsigned k) { return (d + (k + 1) / 2 - 1) % k; });
    case TrafficPattern::neighbour: return each_digit(t, n, [](unsigned d, unsigned k) { return (d + 1) % k; });
    case TrafficPattern::uniform:
    case TrafficPattern::hotspot:
    case TrafficPattern::recorded: break;
  }
  return n;
}

// The physical link a hop leaves by: (node, port); the delivery channel of
// node n is (n, degree).
using LinkKey = std::pair<NodeId, unsigned>;

void add_route(const Topology& t, NodeId from, NodeId to, double weight, std::map<LinkKey, double>& load) {
  for (NodeId at = from; at != to;) {
    const topology::Hop hop = t.next_hop(at, to);
    load[{at, hop.port}] += weight;
    at = t.neighbour(at, hop.port);
  }
  load[{to, t.degree(to)}] += weight;
}

// The load of the busiest link in `load`.
double busiest(const std::map<LinkKey, double>& load) {
  double most = 0;
  for (const auto& [link, l] : load) most = std::max(most, l);
  return most;
}

double seconds_of(csp::VirtualDuration d) { return std::chrono::duration<double>(d).count(); }
csp::VirtualDuration virtual_of(double seconds) {
  return std::chrono::duration_cast<csp::VirtualDuration>(std::chrono::duration<double>(seconds));
}

// What the sources and sinks share: one runtime thread, so plain counters.
struct Tally {
  double window_start = 0, window_end = 0;
  std::uint64_t created = 0, delivered = 0, misdelivered = 0;
  std::uint64_t created_in_window = 0, delivered_in_window = 0;
  unsigned sources_running = 0;
  std::int64_t in_flight = 0;
  double area = 0, last = 0;  // the integral of in_flight over the window, up to `last`
  std::vector<std::vector<double>> created_at;  // per node, per sequence number: creation time
  std::vector<std::vector<std::uint8_t>> seen;  // per node, per sequence number: deliveries
  std::vector<double> latencies;                // of packets created in the window
  std::uint64_t hops = 0;

  void integrate_to(double now) {
    const double to = std::clamp(now, window_start, window_end);
    if (to > last) {
      area += static_cast<double>(in_flight) * (to - std::max(last, window_start));
      last = to;
    }
  }
  bool finished() const { return sources_running == 0 && delivered + misdelivered >= created; }
};

}  // namespace

const std::vector<TrafficPattern>& traffic_patterns() {
  static const std::vector<TrafficPattern> all{TrafficPattern::uniform,      TrafficPattern::transpose,
                                               TrafficPattern::bit_complement, TrafficPattern::bit_reversal,
                                               TrafficPattern::shuffle,      TrafficPattern::tornado,
                                               TrafficPattern::neighbour,    TrafficPattern::hotspot,
                                               TrafficPattern::recorded};
  return all;
}

const char* pattern_name(TrafficPattern pattern) {
  switch (pattern) {
    case TrafficPattern::uniform: return "uniform";
    case TrafficPattern::transpose: return "transpose";
    case TrafficPattern::bit_complement: return "bit-complement";
    case TrafficPattern::bit_reversal: return "bit-reversal";
    case TrafficPattern::shuffle: return "shuffle";
    case TrafficPattern::tornado: return "tornado";
    case TrafficPattern::neighbour: return "neighbour";
    case TrafficPattern::hotspot: return "hotspot";
    case TrafficPattern::recorded: return "render";
  }
  return "?";
}

TrafficPattern parse_traffic_pattern(const std::string& name) {
  std::string known;
  for (const TrafficPattern p : traffic_patterns()) {
    if (name == pattern_name(p)) return p;
    known += (known.empty() ? "" : ", ") + std::string(pattern_name(p));
  }
  throw std::invalid_argument("unknown traffic pattern '" + name + "' (known: " + known + ")");
}

std::string pattern_descriptions() {
  return "uniform: each packet to a node drawn at random among the others\n"
         "transpose: node (x, y) of a square of m x m to (y, x), id = y m + x\n"
         "bit-complement: every bit of the id inverted (2^b nodes)\n"
         "bit-reversal: the id's b bits in reverse order (2^b nodes)\n"
         "shuffle: the id's b bits rotated left by one (2^b nodes)\n"
         "tornado: each digit d of radix k to d + ceil(k/2) - 1 mod k (digits: the grid's x and y, the "
         "ring's or complete graph's index; not on a hypercube, whose digits are bits)\n"
         "neighbour: each digit d of radix k to d + 1 mod k (on a hypercube, every bit)\n"
         "hotspot: a share of the packets (--hotspot) to node 0, the rest uniform\n"
         "render: the packets of a render of --scene on the topology (page requests and replies, work and "
         "results), each node sending its own in their order, at its share of the load, each of its size\n";
}

std::string pattern_unfit(TrafficPattern pattern, const Topology& t) {
  const std::string on = " (" + t.spec() + " has " + std::to_string(t.size()) + " nodes)";
  if (t.size() < 2) return std::string(pattern_name(pattern)) + " traffic needs at least 2 nodes" + on;
  switch (pattern) {
    case TrafficPattern::bit_complement:
    case TrafficPattern::bit_reversal:
    case TrafficPattern::shuffle:
      if (!power_of_two(t)) return std::string(pattern_name(pattern)) + " traffic needs a power-of-two node count" + on;
      break;
    case TrafficPattern::transpose:
      if (square_side(t) == 0) return "transpose traffic needs a square node count, m x m" + on;
      break;
    case TrafficPattern::tornado:
      if (t.kind() == Kind::hypercube) return "tornado traffic is not defined on a hypercube: its digits are bits";
      break;
    case TrafficPattern::uniform:
    case TrafficPattern::neighbour:
    case TrafficPattern::hotspot:
    case TrafficPattern::recorded: break;
  }
  return "";
}

std::vector<NodeId> fixed_destinations(TrafficPattern pattern, const Topology& t) {
  if (pattern == TrafficPattern::uniform || pattern == TrafficPattern::hotspot || pattern == TrafficPattern::recorded)
    return {};
  std::vector<NodeId> to(t.size());
  for (NodeId n = 0; n < t.size(); ++n) to[n] = fixed_destination(pattern, t, n);
  return to;
}

double max_channel_load(const Topology& t, TrafficPattern pattern, double hotspot_fraction) {
  if (const std::string why = pattern_unfit(pattern, t); !why.empty()) throw std::invalid_argument(why);
  if (pattern == TrafficPattern::recorded)
    throw std::invalid_argument("render traffic's channel load depends on its recording (recorded_channel_load)");
  std::map<LinkKey, double> load;
  const auto n = static_cast<NodeId>(t.size());
  const std::vector<NodeId> fixed = fixed_destinations(pattern, t);
  for (NodeId s = 0; s < n; ++s) {
    if (!fixed.empty()) {
      if (fixed[s] != s) add_route(t, s, fixed[s], 1.0, load);
      continue;
    }
    const double hot = pattern == TrafficPattern::hotspot && s != 0 ? hotspot_fraction : 0.0;
    if (hot > 0) add_route(t, s, 0, hot, load);
    for (NodeId d = 0; d < n; ++d)
      if (d != s) add_route(t, s, d, (1.0 - hot) / (n - 1), load);
  }
  return busiest(load);
}

std::uint64_t RecordedTraffic::packets() const {
  std::uint64_t n = 0;
  for (const auto& sent : by_source) n += sent.size();
  return n;
}

namespace {

void check_recorded(const Topology& t, const RecordedTraffic& traffic) {
  if (traffic.by_source.size() != t.size())
    throw std::invalid_argument("render traffic recorded on " + std::to_string(traffic.by_source.size()) +
                                " nodes cannot be offered to " + t.spec() + " (" + std::to_string(t.size()) +
                                " nodes)");
  if (traffic.packets() == 0) throw std::invalid_argument("render traffic: the recording holds no packet");
  for (NodeId s = 0; s < t.size(); ++s)
    for (const RecordedPacket& p : traffic.by_source[s])
      if (p.destination == s || p.destination >= t.size())
        throw std::invalid_argument("render traffic: node " + std::to_string(s) + " sends to node " +
                                    std::to_string(p.destination) + " on " + t.spec());
}

}  // namespace

double recorded_channel_load(const Topology& t, const RecordedTraffic& traffic, const LinkModel& link,
                             std::size_t payload_bytes) {
  check_recorded(t, traffic);
  // A node offers rate n |sent| / total; each of its packets is 1 / |sent| of that.
  const double per_packet = static_cast<double>(t.size()) / static_cast<double>(traffic.packets());
  const double unit = zero_load_latency(link, payload_bytes, 0);
  std::map<LinkKey, double> load;
  for (NodeId s = 0; s < t.size(); ++s)
    for (const RecordedPacket& p : traffic.by_source[s])
      add_route(t, s, p.destination, per_packet * zero_load_latency(link, p.bytes, 0) / unit, load);
  return busiest(load);
}

double recorded_zero_load_latency(const Topology& t, const RecordedTraffic& traffic, const LinkModel& link) {
  check_recorded(t, traffic);
  double sum = 0;
  for (NodeId s = 0; s < t.size(); ++s)
    for (const RecordedPacket& p : traffic.by_source[s])
      sum += zero_load_latency(link, p.bytes, t.distance(s, p.destination));
  return sum / static_cast<double>(traffic.packets());
}

double zero_load_latency(const LinkModel& link, std::size_t payload_bytes, unsigned distance) {
  const double message = std::chrono::duration<double>(link.delay(payload_bytes)).count();
  return (distance + 1) * message;
}

namespace {

// One load point's processes: a source and a sink per node, over the
// network of a virtual-time runtime; what they share is the Tally.
class LoadRun {
 public:
  LoadRun(const Topology& t, TrafficPattern pattern, double offered, const LoadStudyOptions& options)
      : t_(t), pattern_(pattern), offered_(offered), options_(options), fixed_(fixed_destinations(pattern, t)) {
    const double base = recorded() ? recorded_zero_load_latency(t, *options.recorded, options.link)
                                   : zero_load_latency(options.link, options.payload_bytes,
                                                       static_cast<unsigned>(std::ceil(t.average_distance())));
    tally_.window_start = options.warmup_seconds > 0 ? options.warmup_seconds : 20 * base;
    window_ = options.window_seconds > 0 ? options.window_seconds : 200 * base;
    tally_.window_end = tally_.window_start + window_;
    tally_.created_at.resize(t.size());
    tally_.seen.resize(t.size());
    tally_.sources_running = static_cast<unsigned>(t.size());
  }

  LoadResult run() {
    auto record = std::make_shared<csp::VirtualTimeRecord>();
    csp::RuntimeOptions runtime_options;
    runtime_options.threads = 1;
    runtime_options.scheduler = csp::virtual_time_scheduler(record);
    csp::Runtime runtime(runtime_options);
    NetworkOptions net_options;
    net_options.buffer_capacity = options_.buffer_capacity;
    net_options.link = options_.link;
    Network net(runtime, t_, net_options);
    for (NodeId node = 0; node < t_.size(); ++node) {
      runtime.spawn("source " + std::to_string(node), 0,
                    [this, &net, node, out = net.injector(node)]() mutable { source(net, node, out); });
      runtime.spawn("sink " + std::to_string(node), 0,
                    [this, &net, node, in = net.port(node)]() mutable { sink(net, node, in); });
    }
    runtime.run();
    LoadResult r = summary(seconds_of(record->end()));
    r.links = net.stats().links;
    return r;
  }

 private:
  bool recorded() const { return pattern_ == TrafficPattern::recorded; }

  // A node's rate: the offered load, or under recorded traffic its share.
  double rate_of(NodeId node) const {
    if (!recorded()) return offered_;
    const auto& sent = options_.recorded->by_source[node];
    return offered_ * static_cast<double>(t_.size()) * static_cast<double>(sent.size()) /
           static_cast<double>(options_.recorded->packets());
  }

  NodeId destination(NodeId node, std::mt19937_64& rng) const {
    if (!fixed_.empty()) return fixed_[node];
    std::uniform_real_distribution<double> share(0.0, 1.0);
    if (pattern_ == TrafficPattern::hotspot && node != 0 && share(rng) < options_.hotspot_fraction) return 0;
    std::uniform_int_distribution<NodeId> other(0, static_cast<NodeId>(t_.size() - 2));
    const NodeId to = other(rng);
    return to + (to >= node);
  }

  // Creates packets at exponential gaps until the window ends; a packet is
  // created at its instant even if a full injection queue holds the source.
  void source(Network& net, NodeId node, csp::Out<Packet>& out) {
    std::mt19937_64 rng(options_.seed * 0x9e3779b97f4a7c15ull + node);
    Tally& k = tally_;
    const double rate = rate_of(node);
    const std::vector<RecordedPacket>* sent = recorded() ? &options_.recorded->by_source[node] : nullptr;
    if (!(rate > 0)) {  // a node the recording has send nothing
      if (--k.sources_running == 0 && k.finished()) net.shutdown();
      return;
    }
    std::exponential_distribution<double> gap(rate);
    std::size_t index = 0;
    for (double next = gap(rng); next <= k.window_end; next += gap(rng)) {
      const double at = seconds_of(virtual_of(next));  // an instant of the virtual clock
      const RecordedPacket* replayed = sent ? &(*sent)[index++ % sent->size()] : nullptr;
      const NodeId to = replayed ? replayed->destination : destination(node, rng);
      if (to == node) break;  // a fixed pattern that maps this node to itself: it sends nothing
      if (at > seconds_of(csp::this_process::now()))
        csp::this_process::advance(virtual_of(next) - csp::this_process::now());
      Packet p;
      p.destination = to;
      p.kind = kind_traffic;
      p.id = (std::uint64_t{node} << 32) | k.created_at[node].size();
      p.payload.resize(replayed ? replayed->bytes : options_.payload_bytes);
      // Its wait for a full injection queue counts as time in the network.
      const double held = seconds_of(csp::this_process::now());
      k.integrate_to(held);
      k.area += std::max(0.0, std::min(held, k.window_end) - std::max(at, k.window_start));
      ++k.in_flight;
      ++k.created;
      k.created_at[node].push_back(at);
      k.seen[node].push_back(0);
      if (at >= k.window_start) ++k.created_in_window;
      out.write(std::move(p));
    }
    if (--k.sources_running == 0 && k.finished()) net.shutdown();
  }

  // Checks and times every packet delivered to `node`; the last delivery of
  // the run shuts the network down.
  void sink(Network& net, NodeId node, csp::In<Packet>& in) {
    Tally& k = tally_;
    const auto n = static_cast<NodeId>(t_.size());
    try {
      for (;;) {
        const Packet p = in.read();
        const double now = seconds_of(csp::this_process::now());
        const auto source = static_cast<NodeId>(p.id >> 32);
        const auto sequence = static_cast<std::size_t>(p.id & 0xffffffffu);
        if (p.destination != node || source >= n || sequence >= k.seen[source].size() ||
            k.seen[source][sequence]++ != 0) {
          ++k.misdelivered;
        } else {
          k.integrate_to(now);
          --k.in_flight;
          ++k.delivered;
          const double created = k.created_at[source][sequence];
          if (now >= k.window_start && now <= k.window_end) ++k.delivered_in_window;
          if (created >= k.window_start && created <= k.window_end) {
            k.latencies.push_back(now - created);
            k.hops += p.hops;
          }
        }
        if (k.finished()) net.shutdown();
      }
    } catch (const csp::Poisoned&) {
      // the study is over
    }
  }

  LoadResult summary(double end_seconds) {
    Tally& k = tally_;
    k.integrate_to(k.window_end);
    LoadResult r;
    r.offered = offered_;
    r.created = k.created;
    r.delivered = k.delivered;
    r.misdelivered = k.misdelivered;
    r.measured = k.latencies.size();
    r.accepted = static_cast<double>(k.delivered_in_window) / (window_ * static_cast<double>(t_.size()));
    r.arrival_rate = static_cast<double>(k.created_in_window) / window_;
    r.mean_in_flight = k.area / window_;
    r.end_seconds = end_seconds;
    std::vector<double>& l = k.latencies;
    if (l.empty()) return r;
    double sum = 0;
    for (const double x : l) sum += x;
    r.mean_latency = sum / static_cast<double>(l.size());
    r.mean_hops = static_cast<double>(k.hops) / static_cast<double>(l.size());
    const auto at = [&l](double q) {
      const auto i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(l.size()))) - 1;
      std::nth_element(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(i), l.end());
      return l[i];
    };
    r.p50_latency = at(0.5);
    r.p99_latency = at(0.99);
    r.max_latency = *std::max_element(l.begin(), l.end());
    return r;
  }

  const Topology& t_;
  const TrafficPattern pattern_;
  const double offered_;
  const LoadStudyOptions& options_;
  const std::vector<NodeId> fixed_;
  double window_ = 0;
  Tally tally_;
};

}  // namespace

LoadResult run_load(const Topology& t, TrafficPattern pattern, double offered, const LoadStudyOptions& options) {
  if (const std::string why = pattern_unfit(pattern, t); !why.empty()) throw std::invalid_argument(why);
  if (!options.link.enabled()) throw std::invalid_argument("a load study needs a link model: a latency or a bandwidth");
  if (!(offered > 0)) throw std::invalid_argument("an offered load must be above 0");
  if (pattern == TrafficPattern::recorded) {
    if (!options.recorded) throw std::invalid_argument("render traffic needs its recording");
    check_recorded(t, *options.recorded);
  }
  return LoadRun(t, pattern, offered, options).run();
}

}  // namespace nodes
