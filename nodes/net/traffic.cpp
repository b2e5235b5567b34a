// Traffic patterns and the sender/receiver driver (see traffic.hpp).
#include "nodes/net/traffic.hpp"

#include <atomic>
#include <bit>
#include <chrono>
#include <random>
#include <stdexcept>

namespace nodes {
namespace {

NodeId reverse_bits(NodeId n, unsigned bits) {
  NodeId r = 0;
  for (unsigned i = 0; i < bits; ++i) r |= ((n >> i) & 1u) << (bits - 1 - i);
  return r;
}

std::vector<Packet> packets_of(NodeId node, const std::vector<NodeId>& dsts, std::uint64_t first_id,
                               std::size_t payload) {
  std::vector<Packet> packets;
  packets.reserve(dsts.size());
  for (NodeId d : dsts) {
    Packet p;
    p.destination = d;
    p.kind = kind_traffic;
    p.id = first_id++;
    p.payload.assign(payload, std::byte{static_cast<unsigned char>(node)});
    packets.push_back(std::move(p));
  }
  return packets;
}

}  // namespace

Pattern parse_pattern(const std::string& name) {
  if (name == "uniform") return Pattern::uniform;
  if (name == "all-to-one") return Pattern::all_to_one;
  if (name == "all-to-all") return Pattern::all_to_all;
  if (name == "bit-reversal") return Pattern::bit_reversal;
  throw std::invalid_argument("unknown pattern '" + name +
                              "' (expected uniform, all-to-one, all-to-all or bit-reversal)");
}

TrafficPlan make_plan(Pattern pattern, std::size_t nodes, std::size_t packets, std::uint32_t seed) {
  TrafficPlan plan(nodes);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<NodeId> pick(0, static_cast<NodeId>(nodes - 1));
  const auto bits = static_cast<unsigned>(std::countr_zero(nodes));
  if (pattern == Pattern::bit_reversal && !std::has_single_bit(nodes))
    throw std::invalid_argument("bit-reversal traffic needs a power-of-two node count, not " +
                                std::to_string(nodes));
  const std::size_t rounds = nodes > 1 ? std::max<std::size_t>(1, packets / (nodes - 1)) : 0;
  for (NodeId n = 0; n < nodes; ++n) {
    auto& dsts = plan[n];
    switch (pattern) {
      case Pattern::uniform:
        for (std::size_t i = 0; i < packets; ++i) dsts.push_back(pick(rng));
        break;
      case Pattern::all_to_one: dsts.assign(packets, 0); break;
      case Pattern::bit_reversal: dsts.assign(packets, reverse_bits(n, bits)); break;
      case Pattern::all_to_all:
        for (std::size_t r = 0; r < rounds; ++r)
          for (NodeId m = 1; m < nodes; ++m) dsts.push_back((n + m) % static_cast<NodeId>(nodes));
        break;
    }
  }
  return plan;
}

TrafficResult run_traffic(const topology::Topology& topology, const TrafficPlan& plan,
                          const NetworkOptions& options, unsigned threads, std::size_t payload) {
  csp::Runtime runtime(threads);
  Network net(runtime, topology, options);
  const std::size_t n = topology.size();
  std::vector<std::uint64_t> expected(n, 0), first_id(n + 1, 0);
  for (NodeId node = 0; node < n; ++node) {
    for (NodeId d : plan[node]) ++expected[d];
    first_id[node + 1] = first_id[node] + plan[node].size();
  }
  std::vector<std::uint8_t> seen(first_id[n], 0);  // each id is written by its one receiver
  std::vector<std::uint64_t> wrong(n, 0);
  std::atomic<std::size_t> unfinished{n};
  for (NodeId node = 0; node < n; ++node) {
    runtime.spawn("send " + std::to_string(node), net.thread_of(node),
                  [out = net.injector(node), packets = packets_of(node, plan[node], first_id[node],
                                                                  payload)]() mutable {
                    for (auto& p : packets) out.write(std::move(p));
                  });
    runtime.spawn("receive " + std::to_string(node), net.thread_of(node),
                  [&, node, in = net.port(node)]() mutable {
                    for (std::uint64_t i = 0; i < expected[node]; ++i) {
                      const Packet p = in.read();
                      if (p.destination != node || p.id >= seen.size() || seen[p.id]++) ++wrong[node];
                    }
                    if (--unfinished == 0) net.shutdown();
                  });
  }
  const auto start = std::chrono::steady_clock::now();
  runtime.run();
  TrafficResult result;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.stats = net.stats();
  result.sent = first_id[n];
  for (std::uint8_t s : seen) result.delivered += s == 1;
  for (std::uint64_t w : wrong) result.misdelivered += w;
  return result;
}

}  // namespace nodes
