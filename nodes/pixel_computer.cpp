// Pixel computer process (see pixel_computer.hpp).
#include "nodes/pixel_computer.hpp"

#include <stdexcept>
#include <string>

namespace nodes {

namespace {

Packet expect(csp::In<Packet>& in, MessageKind a, MessageKind b) {
  Packet p = in.read();
  const auto kind = static_cast<MessageKind>(p.kind);
  if (kind != a && kind != b)
    throw std::logic_error("pixel computer got an unexpected " + std::string(message_kind_name(p.kind)) + " message");
  return p;
}

}  // namespace

PixelComputer::PixelComputer(std::uint16_t port, SvmSource& source, const tracer::DatabaseHeader& header,
                             tracer::TraceOptions options, ItemGrid grid, csp::In<Packet> in, Outbox& out,
                             WorkerCounters& counters, std::function<void()> after_tile)
    : port_(port),
      source_(source),
      tracer_(header, source, options),
      grid_(grid),
      in_(std::move(in)),
      out_(out),
      counters_(counters),
      after_tile_(std::move(after_tile)) {}

void PixelComputer::run() {
  for (;;) {
    source_.release();  // about to block: another worker may evict our page
    out_.send(make_packet(0, Ports::farmer, MessageKind::work_request, encode_port(port_)));
    const Packet answer = expect(in_, MessageKind::work, MessageKind::stop);
    if (static_cast<MessageKind>(answer.kind) == MessageKind::stop) break;
    const Tile tile = decode_tile(answer.payload);
    compute(tile);
    source_.release();  // before the hook too: it may suspend this fiber
    if (after_tile_) after_tile_();
    out_.send(make_packet(0, Ports::collector, MessageKind::result, encode_result(tile, colors_)));
  }
  out_.send(make_packet(0, Ports::farmer, MessageKind::worker_done));
}

void PixelComputer::compute(Tile tile) {
  colors_.resize(tile.count);
  for (std::uint32_t i = 0; i < tile.count; ++i) {
    const auto item = static_cast<int>(tile.first + i);
    const int x = item % grid_.width;
    const int y = item / grid_.width;
    colors_[i] = grid_.corners ? tracer_.trace_sample(x, y, counters_.rays) : tracer_.trace_pixel(x, y, counters_.rays);
  }
  counters_.items += tile.count;
  ++counters_.tiles;
}

PageFetch make_page_fetch(const PagePlacement& placement, std::uint16_t port, csp::In<Packet> in,
                          Outbox& out) {
  return [&placement, port, in, &out](std::uint32_t page) mutable {
    const auto owner = static_cast<NodeId>(placement.owner(page));
    out.send(make_packet(owner, Ports::page_server, MessageKind::page_request, encode_page_request({page, port})));
    return expect(in, MessageKind::page_reply, MessageKind::page_reply).payload;
  };
}

}  // namespace nodes
