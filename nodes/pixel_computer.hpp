// A pixel computer: one fiber that asks the farmer for work, traces it
// through its node's shared virtual memory and sends the colours to the
// frame collector. A processor runs one or more (--workers-per-node), so page
// waits of one overlap with tracing by another.
//
// Protocol, on its own local port (Ports::first_worker + w):
//   -> farmer     work_request {my port}
//   <- farmer     work {first, count}  |  stop
//   -> collector  result {first, count, colours}      (after work)
//   -> farmer     worker_done                         (after stop; then ends)
// While tracing, a cache miss sends page_request to the page's owner and
// reads this same port for the page_reply (make_page_fetch): the worker has
// at most one request outstanding, so its port never holds more than one
// packet and the next packet is always the awaited answer.
#pragma once

#include <cstdint>
#include <functional>

#include "csp/csp.hpp"
#include "nodes/messages.hpp"
#include "nodes/svm.hpp"
#include "tracer/render.hpp"

namespace nodes {

struct WorkerCounters {
  std::uint64_t items = 0;  // pixels (or SPD corner samples) computed
  std::uint64_t tiles = 0;
  tracer::RayStats rays;
};

// What a work item is: a pixel (x, y) in scanline order, or an SPD corner
// sample on the (W+1) x (H+1) grid.
struct ItemGrid {
  int width = 0;  // items per row
  bool corners = false;
};

class PixelComputer {
 public:
  PixelComputer(std::uint16_t port, SvmSource& source, const tracer::DatabaseHeader& header,
                tracer::TraceOptions options, ItemGrid grid, csp::In<Packet> in, Outbox& out,
                WorkerCounters& counters, std::function<void()> after_tile = {});
  void run();

 private:
  void compute(Tile tile);

  std::uint16_t port_;
  SvmSource& source_;
  tracer::Tracer tracer_;
  ItemGrid grid_;
  csp::In<Packet> in_;
  Outbox& out_;
  WorkerCounters& counters_;
  std::vector<tracer::Color> colors_;
  std::function<void()> after_tile_;  // before the result is sent: virtual time charges the work here
};

// The miss path of a worker's SvmSource: page_request to the owner, then
// block on the worker's port for the page_reply.
PageFetch make_page_fetch(const PagePlacement& placement, std::uint16_t port, csp::In<Packet> in,
                          Outbox& out);

}  // namespace nodes
