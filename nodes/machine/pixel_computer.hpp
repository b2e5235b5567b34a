// A pixel computer: one fiber that asks the farmer for work, traces it
// through its node's shared virtual memory and sends the colours back. A
// processor runs one or more (Shape::workers_per_node), so page waits of one
// overlap with tracing by another.
//
// It reads only its own local port (Ports::first_worker + w): the farmer's
// work and stop answers, P + 1 always owed to it (P = prefetch), and the
// page_reply to each of its misses (make_page_fetch); answers that arrive
// while it waits for a page are kept, in order, for later. It sends a result
// after each tile and worker_done once every answer is in, then ends; its
// node's observer (node_observer.hpp) hears of each miss and each tile. On
// several threads it runs at low priority and yields every `timeslice`
// items, and with few pixel computers a thread lets a packet for its thread
// be handled after any item (`answer_at_once`). The protocol and why the
// port drains: docs/architecture.md ("The path of one pixel" and after).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <span>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/machine/messages.hpp"
#include "nodes/machine/node_observer.hpp"
#include "nodes/machine/pixel_order.hpp"
#include "nodes/machine/svm.hpp"
#include "tracer/render.hpp"

namespace nodes {

// Seconds since the run began: wall time, or the calling process's virtual
// clock under virtual time.
using RunClock = std::function<double()>;

// One tile as its worker traced it, for timelines of the farming: from the
// tile's first item to its result leaving (virtual time: after its work was
// charged), and the page requests and rays it took.
struct TileSpan {
  int worker = 0;  // on its node
  Tile tile;
  double start = 0;
  double end = 0;
  std::uint64_t page_requests = 0;
  std::uint64_t rays = 0;
};

struct WorkerCounters {
  std::uint64_t items = 0;  // pixels (or SPD corner samples) computed
  std::uint64_t tiles = 0;
  tracer::RayStats rays;
  std::vector<TileSpan> spans;  // one per tile, in order, when the machine records them
};

// What a work item is: a pixel (x, y), or an SPD corner sample on the
// (W+1) x (H+1) grid, numbered in the machine's pixel order.
struct ItemGrid {
  int width = 0;  // items per row
  bool corners = false;
  std::span<const std::uint32_t> positions;  // item -> scanline position; empty: scanline order

  std::uint32_t position(std::uint32_t item) const { return scanline_position(positions, item); }
};

// A worker's network port, shared by its two readers: the work loop (work
// and stop answers) and the miss path (page replies). One fiber uses it.
class WorkerPort {
 public:
  explicit WorkerPort(csp::In<Packet> in) : in_(std::move(in)) {}
  Packet next_answer();  // work or stop
  Packet page_reply();   // keeps any answers that arrive first

 private:
  csp::In<Packet> in_;
  std::deque<Packet> answers_;  // arrived while waiting for a page
};

// What a pixel computer traces: the frame's items (grid) of the scene whose
// header this is, under these options. The header outlives the process.
struct TraceWork {
  const tracer::DatabaseHeader& header;
  tracer::TraceOptions options;
  ItemGrid grid;
};

// Where a pixel computer stands on its node: its port (Ports::first_worker +
// its index), its view of the node's memory, the port it reads, the outbox
// it sends on and the counters it fills. All outlive the process.
struct WorkerLinks {
  std::uint16_t port;
  SvmSource& source;
  WorkerPort& in;
  Outbox& out;
  WorkerCounters& counters;
};

// How a pixel computer paces its work, and who watches it.
struct WorkerPacing {
  std::uint16_t prefetch = 0;        // tiles asked for beyond the one traced (Farming::prefetch)
  std::uint32_t timeslice = 0;       // items traced between two csp::yield()s; 0: never yield
  bool answer_at_once = false;       // after any item, csp::yield_to_urgent() when csp::yield_requested()
  bool answer_between_rays = false;  // the same before every ray (Tracer::set_ray_hook): alone on its thread
  NodeObserver* observer = nullptr;  // told of each tile before its result is sent; null: nobody
  RunClock clock;                    // set: record a TileSpan per tile
};

class PixelComputer {
 public:
  PixelComputer(const TraceWork& work, const WorkerLinks& links, WorkerPacing pacing = {});
  void run();

 private:
  void compute(Tile tile);
  int worker() const { return links_.port - Ports::first_worker; }

  WorkerLinks links_;
  WorkerPacing pacing_;
  tracer::Tracer tracer_;
  ItemGrid grid_;
  std::vector<tracer::Color> colors_;
};

// The miss path of a worker's SvmSource: page_request to the owner, then
// wait on the worker's port for the page_reply; the node's observer, if
// any, is told as the request leaves and as the page arrives.
PageFetch make_page_fetch(const PagePlacement& placement, std::uint16_t port, WorkerPort& in, Outbox& out,
                          NodeObserver* observer = nullptr);

}  // namespace nodes
