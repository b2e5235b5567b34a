// Pixel computer process (see pixel_computer.hpp).
#include "nodes/machine/pixel_computer.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace nodes {

namespace {

bool is_answer(const Packet& p) {
  const auto kind = static_cast<MessageKind>(p.kind);
  return kind == MessageKind::work || kind == MessageKind::stop;
}

[[noreturn]] void unexpected(const Packet& p) {
  throw std::logic_error("pixel computer got an unexpected " + std::string(message_kind_name(p.kind)) + " message");
}

}  // namespace

Packet WorkerPort::next_answer() {
  if (!answers_.empty()) {
    Packet p = std::move(answers_.front());
    answers_.pop_front();
    return p;
  }
  Packet p = in_.read();
  if (!is_answer(p)) unexpected(p);
  return p;
}

Packet WorkerPort::page_reply() {
  for (;;) {
    Packet p = in_.read();
    if (static_cast<MessageKind>(p.kind) == MessageKind::page_reply) return p;
    if (!is_answer(p)) unexpected(p);
    answers_.push_back(std::move(p));
  }
}

PixelComputer::PixelComputer(std::uint16_t port, std::uint16_t prefetch, SvmSource& source,
                             const tracer::DatabaseHeader& header, tracer::TraceOptions options, ItemGrid grid,
                             WorkerPort& in, Outbox& out, WorkerCounters& counters, std::function<void()> after_tile,
                             std::uint32_t timeslice, RunClock clock)
    : port_(port),
      prefetch_(prefetch),
      source_(source),
      tracer_(header, source, options),
      grid_(grid),
      in_(in),
      out_(out),
      counters_(counters),
      after_tile_(std::move(after_tile)),
      timeslice_(timeslice),
      clock_(std::move(clock)) {}

void PixelComputer::run() {
  std::uint32_t owed = prefetch_ + 1u;  // answers the farmer still has to send
  out_.send(make_packet(0, Ports::farmer, MessageKind::work_request,
                        encode_work_request({port_, static_cast<std::uint16_t>(owed)})));
  while (owed > 0) {
    source_.release();  // about to block: another worker may evict our page
    const Packet answer = in_.next_answer();
    --owed;
    if (static_cast<MessageKind>(answer.kind) == MessageKind::stop) continue;
    const Tile tile = decode_tile(answer.payload);
    const double start = clock_ ? clock_() : 0.0;
    const std::uint64_t requests_before = source_.stats().misses;
    const std::uint64_t rays_before = counters_.rays.rays();
    compute(tile);
    source_.release();  // before the hook too: it may suspend this fiber
    if (after_tile_) after_tile_();
    if (clock_)
      counters_.spans.push_back({port_ - Ports::first_worker, tile, start, clock_(),
                                 source_.stats().misses - requests_before, counters_.rays.rays() - rays_before});
    out_.send(make_packet(0, Ports::farmer, MessageKind::result, encode_result(port_, tile, colors_)));
    ++owed;
  }
  out_.send(make_packet(0, Ports::farmer, MessageKind::worker_done));
}

void PixelComputer::compute(Tile tile) {
  colors_.resize(tile.count);
  for (std::uint32_t i = 0; i < tile.count; ++i) {
    const auto position = static_cast<int>(grid_.position(tile.first + i));
    const int x = position % grid_.width;
    const int y = position / grid_.width;
    colors_[i] = grid_.corners ? tracer_.trace_sample(x, y, counters_.rays) : tracer_.trace_pixel(x, y, counters_.rays);
    // Between samples: the tracer asks for every page anew at a sample's start.
    if (timeslice_ > 0 && (i + 1) % timeslice_ == 0) {
      source_.release();  // another worker of the node may run and evict our page
      csp::yield();
    }
  }
  counters_.items += tile.count;
  ++counters_.tiles;
}

PageFetch make_page_fetch(const PagePlacement& placement, std::uint16_t port, WorkerPort& in, Outbox& out) {
  return [&placement, port, &in, &out](std::uint32_t page) {
    const auto owner = static_cast<NodeId>(placement.owner(page));
    out.send(make_packet(owner, Ports::page_server, MessageKind::page_request, encode_page_request({page, port})));
    return in.page_reply();
  };
}

}  // namespace nodes
