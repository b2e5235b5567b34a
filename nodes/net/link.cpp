// Link process: take a packet from the router's queue, carry it, hand it on.
#include "nodes/net/link.hpp"

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

Link::Link(csp::In<Packet> queue, csp::Out<Packet> next, LinkModel model)
    : queue_(std::move(queue)), next_(std::move(next)), model_(model) {}

void Link::run() {
  for (;;) {
    Packet packet = queue_.read();
    csp::this_process::delay(model_.delay(packet.bytes()));
    next_.write(std::move(packet));
  }
}

}  // namespace nodes
