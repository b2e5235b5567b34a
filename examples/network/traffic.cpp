// traffic: sends a synthetic traffic pattern over a topology and prints what
// the network did (throughput, hops against the analytic average distance,
// busiest link, traced routes, the deadlock analysis of the routing).
//
//   traffic --topology hypercube:6 --pattern uniform --packets 1000
//           --payload 64 --threads 2 --trace-routes 5 --buffer 1
#include <boost/program_options.hpp>

#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include "nodes/net/traffic.hpp"
#include "topology/deadlock.hpp"
#include "topology/spec.hpp"

namespace po = boost::program_options;

namespace {

struct Options {
  std::string topology = "hypercube:6";
  std::optional<std::size_t> nodes;
  std::string pattern = "uniform";
  std::size_t packets = 1000;
  std::size_t payload = 64;
  unsigned threads = 2;
  std::uint64_t trace_routes = 0;
  std::size_t buffer = 4;
  double latency_us = 0;
  double bandwidth_mbs = 0;
};

// Returns nullopt after printing help.
std::optional<Options> parse_options(int argc, char** argv) {
  Options o;
  std::size_t nodes = 0;
  po::options_description desc("traffic options");
  desc.add_options()("help,h", "show this help")
      ("topology", po::value(&o.topology)->default_value(o.topology), "hypercube:D, mesh:WxH, torus:WxH, ring:N, complete:N, or a bare kind with --nodes")
      ("nodes", po::value(&nodes), "node count for a bare kind")
      ("pattern", po::value(&o.pattern)->default_value(o.pattern), "uniform, all-to-one, all-to-all, bit-reversal")
      ("packets", po::value(&o.packets)->default_value(o.packets), "packets per node")
      ("payload", po::value(&o.payload)->default_value(o.payload), "payload bytes per packet")
      ("threads", po::value(&o.threads)->default_value(o.threads), "OS threads")
      ("trace-routes", po::value(&o.trace_routes)->default_value(0), "print the routes of the first N packets")
      ("buffer", po::value(&o.buffer)->default_value(o.buffer), "packets per link queue (>= 1)")
      ("latency-us", po::value(&o.latency_us)->default_value(0), "link latency per hop, microseconds")
      ("bandwidth-mbs", po::value(&o.bandwidth_mbs)->default_value(0), "link bandwidth, MB/s (0: unlimited; iPSC/2: 2.8)");
  po::variables_map vm;
  po::store(po::command_line_parser(argc, argv).options(desc).run(), vm);
  po::notify(vm);
  if (vm.count("help")) {
    std::cout << desc;
    return std::nullopt;
  }
  if (vm.count("nodes")) o.nodes = nodes;
  if (o.buffer == 0) throw po::error("--buffer must be at least 1");
  if (o.threads == 0 || o.threads > 64) throw po::error("--threads must be between 1 and 64");
  if (o.payload > (1u << 20)) throw po::error("--payload must be at most 1 MiB");
  if (o.latency_us < 0 || o.bandwidth_mbs < 0) throw po::error("--latency-us and --bandwidth-mbs must not be negative");
  return o;
}

void report(const topology::Topology& t, const nodes::TrafficResult& r) {
  const auto kind_name = [](std::uint8_t k) {
    return k == nodes::kind_traffic ? std::string("packet") : "kind " + std::to_string(k);
  };
  for (const auto& route : r.stats.routes) std::cout << nodes::format_route(route, kind_name) << "\n";
  std::printf("%llu packets sent, %llu delivered once, %llu misdelivered, %.3f s, %.0f packets/s\n",
              static_cast<unsigned long long>(r.sent), static_cast<unsigned long long>(r.delivered),
              static_cast<unsigned long long>(r.misdelivered), r.seconds,
              r.seconds > 0 ? static_cast<double>(r.delivered) / r.seconds : 0.0);
  std::cout << nodes::format_summary(r.stats, t, kind_name);
  if (t.size() > 1024) return;  // the N^2 analysis is for machines of testable size
  std::cout << "routing " << topology::analyse_deadlock_free(t).describe() << " ("
            << t.buffer_classes() << " buffer class" << (t.buffer_classes() > 1 ? "es" : "")
            << "); single class: " << topology::analyse_naive(t).describe() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<Options> options;
  topology::Topology t = topology::Topology::ring(1);
  nodes::TrafficPlan plan;
  try {
    options = parse_options(argc, argv);
    if (!options) return 0;
    t = topology::parse_topology(options->topology, options->nodes);
    plan = nodes::make_plan(nodes::parse_pattern(options->pattern), t.size(), options->packets, 1);
  } catch (const std::exception& e) {
    std::cerr << "traffic: " << e.what() << "\n";
    return 2;
  }
  nodes::NetworkOptions net;
  net.buffer_capacity = options->buffer;
  net.trace_routes = options->trace_routes;
  net.link.latency = std::chrono::nanoseconds(static_cast<std::int64_t>(options->latency_us * 1e3));
  net.link.bytes_per_second = options->bandwidth_mbs * 1e6;
  try {
    const auto result = nodes::run_traffic(t, plan, net, options->threads, options->payload);
    report(t, result);
    return result.delivered == result.sent && result.misdelivered == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "traffic: " << e.what() << "\n";
    return 1;
  }
}
