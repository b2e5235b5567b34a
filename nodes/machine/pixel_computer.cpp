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

PixelComputer::PixelComputer(const TraceWork& work, const WorkerLinks& links, WorkerPacing pacing)
    : links_(links), pacing_(std::move(pacing)), tracer_(work.header, links.source, work.options), grid_(work.grid) {
  // Alone on its thread, nothing else reads this pixel computer's pages while
  // it lets the relay and the servers run, so it may do so between rays.
  if (pacing_.answer_between_rays)
    tracer_.set_ray_hook(
        [](void*) {
          if (csp::yield_requested()) csp::yield_to_urgent();
        },
        nullptr);
}

void PixelComputer::run() {
  SvmSource& source = links_.source;
  WorkerCounters& counters = links_.counters;
  const RunClock& clock = pacing_.clock;
  std::uint32_t owed = pacing_.prefetch + 1u;  // answers the farmer still has to send
  links_.out.send(make_packet(0, Ports::farmer, MessageKind::work_request,
                              encode_work_request({links_.port, static_cast<std::uint16_t>(owed)})));
  while (owed > 0) {
    source.release();  // about to block: another worker may evict our page
    const Packet answer = links_.in.next_answer();
    --owed;
    if (static_cast<MessageKind>(answer.kind) == MessageKind::stop) continue;
    const Tile tile = decode_tile(answer.payload);
    const double start = clock ? clock() : 0.0;
    const std::uint64_t requests_before = source.stats().misses;
    const std::uint64_t rays_before = counters.rays.rays();
    compute(tile);
    source.release();  // before the observer too: it may suspend this fiber
    if (pacing_.observer) pacing_.observer->tile_done(worker(), source.stats());
    if (clock)
      counters.spans.push_back({worker(), tile, start, clock(), source.stats().misses - requests_before,
                                counters.rays.rays() - rays_before});
    links_.out.send(make_packet(0, Ports::farmer, MessageKind::result, encode_result(links_.port, tile, colors_)));
    ++owed;
  }
  links_.out.send(make_packet(0, Ports::farmer, MessageKind::worker_done));
}

void PixelComputer::compute(Tile tile) {
  WorkerCounters& counters = links_.counters;
  colors_.resize(tile.count);
  for (std::uint32_t i = 0; i < tile.count; ++i) {
    const auto position = static_cast<int>(grid_.position(tile.first + i));
    const int x = position % grid_.width;
    const int y = position / grid_.width;
    colors_[i] = grid_.corners ? tracer_.trace_sample(x, y, counters.rays) : tracer_.trace_pixel(x, y, counters.rays);
    // Between samples: the tracer asks for every page anew at a sample's start.
    if (pacing_.timeslice > 0 && (i + 1) % pacing_.timeslice == 0) {
      links_.source.release();  // another worker of the node may run and evict our page
      csp::yield();
    } else if (pacing_.answer_at_once && csp::yield_requested()) {
      // A packet reached this thread (a page request, say, that another
      // thread's pixel computer waits on): the relay and the servers run now,
      // and this pixel computer goes on before the thread's others.
      links_.source.release();
      csp::yield_to_urgent();
    }
  }
  counters.items += tile.count;
  ++counters.tiles;
}

PageFetch make_page_fetch(const PagePlacement& placement, std::uint16_t port, WorkerPort& in, Outbox& out,
                          NodeObserver* observer) {
  return [&placement, port, &in, &out, observer](std::uint32_t page) {
    const int worker = port - Ports::first_worker;
    if (observer) observer->fetch_started(worker, page);
    const auto owner = static_cast<NodeId>(placement.owner(page));
    out.send(make_packet(owner, Ports::page_server, MessageKind::page_request, encode_page_request({page, port})));
    Packet reply = in.page_reply();
    if (observer) observer->fetch_ended(worker, page);
    return reply;
  };
}

}  // namespace nodes
