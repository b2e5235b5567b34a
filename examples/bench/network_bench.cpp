// network_bench: packets per second through the store-and-forward network
// for each topology at 64 nodes on 2 threads, uniform random traffic with
// 64-byte and 1 KiB payloads, and the measured mean hops beside the analytic
// average distance (they differ only by the self-addressed packets, which
// travel 0 hops). All rows are measured in the same run, side by side.
//
//   network_bench [packets-per-node]     (default 500)
#include <cstdio>
#include <cstdlib>
#include <string>

#include "examples/bench/bench_args.hpp"
#include "nodes/net/traffic.hpp"
#include "topology/spec.hpp"

namespace {

const char* const usage = "usage: network_bench [PACKETS_PER_NODE]   (1..1000000, default 500)\n";

int bench_network(const std::vector<std::string>& args) {
  if (args.size() > 1) throw bench::BadArgument{"too many arguments"};
  const auto per_node =
      args.empty() ? std::size_t{500}
                   : static_cast<std::size_t>(bench::parse_int(args[0], 1, 1000000, "PACKETS_PER_NODE"));
  std::printf("%-14s %8s %10s %12s %10s %10s %10s\n", "topology", "payload", "packets",
              "packets/s", "rel", "mean hops", "analytic");
  for (std::size_t payload : {64u, 1024u}) {
    double baseline = 0;
    for (const char* spec : {"complete:64", "hypercube:6", "torus:8x8", "mesh:8x8", "ring:64"}) {
      const auto t = topology::parse_topology(spec);
      const auto plan = nodes::make_plan(nodes::Pattern::uniform, t.size(), per_node, 42);
      const auto r = nodes::run_traffic(t, plan, nodes::NetworkOptions{}, 2, payload);
      if (r.delivered != r.sent || r.misdelivered != 0) {
        std::fprintf(stderr, "network_bench: %s lost or misdelivered packets\n", spec);
        return 1;
      }
      const double rate = static_cast<double>(r.delivered) / r.seconds;
      if (baseline == 0) baseline = rate;
      std::printf("%-14s %8zu %10llu %12.0f %9.2fx %10.3f %10.3f\n", spec, payload,
                  static_cast<unsigned long long>(r.delivered), rate, rate / baseline,
                  r.stats.hops.mean(), t.average_distance());
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return bench::run_main("network_bench", usage, argc, argv, bench_network); }
