// Link process: pull a packet from the router, carry it, hand it on.
#include "nodes/link.hpp"

#include <utility>

#include "csp/virtual_time.hpp"

namespace nodes {

std::chrono::nanoseconds LinkModel::delay(std::size_t bytes) const {
  auto d = latency;
  if (bytes_per_second > 0.0)
    d += std::chrono::nanoseconds(
        static_cast<std::int64_t>(static_cast<double>(bytes) * 1e9 / bytes_per_second));
  return d;
}

Link::Link(csp::Out<Ready> request, csp::In<Packet> reply, csp::Out<Packet> next, LinkModel model,
           LinkCounters& counters)
    : request_(std::move(request)),
      reply_(std::move(reply)),
      next_(std::move(next)),
      model_(model),
      counters_(counters) {}

void Link::run() {
  for (;;) {
    request_.write(Ready{});
    Packet packet = reply_.read();
    ++counters_.packets;
    counters_.bytes += packet.payload.size();
    if (model_.enabled()) csp::this_process::delay(model_.delay(packet.payload.size()));
    next_.write(std::move(packet));
  }
}

}  // namespace nodes
