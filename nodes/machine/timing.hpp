// Virtual timing of the machine: what a run would take on a real
// distributed-memory computer with given per-operation costs.
//
// CostModel holds the costs: counted work (BVH box tests, ray-primitive
// tests, rays, page-table operations) scaled by one factor `unit`, the
// constant fitted to a published time; per message, hop + bytes / bandwidth
// on every link and on the delivery stage, and `msg` at each end in a pixel
// computer or page server; `serve` per page request served, taken from its
// node's pixel computers too. MachineTiming holds the hooks that make a
// nodes::run_machine run charge those costs under csp's virtual-time
// scheduler (csp/virtual_time.hpp): the whole machine runs on one thread, and
// the predicted synthesis time is the virtual time at which the run ends.
// Deterministic: the same run gives the same time and statistics. What is
// charged when: docs/architecture.md, "Virtual time".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "csp/runtime.hpp"
#include "csp/virtual_time.hpp"
#include "nodes/machine/node_observer.hpp"
#include "nodes/machine/svm.hpp"
#include "nodes/net/link.hpp"
#include "tracer/stats.hpp"

namespace nodes {

struct CostModel {
  std::string name = "custom";
  double unit = 1.0;         // scales every compute cost (the fitted constant)
  double box = 0;            // seconds per box test (before unit)
  double prim = 0;           // seconds per ray-primitive test
  double shade = 0;          // seconds per ray: set-up, shading, spawning
  double page = 0;           // seconds per page-table operation
  double serve = 0;          // seconds per page request handled by a page server
  double msg = 0;            // processor seconds per message sent or received
  double hop = 0;            // seconds per link crossed (and per delivery)
  double bandwidth = 0;      // link bytes per second; 0: infinitely fast

  double compute_seconds(const tracer::RayStats& rays) const;  // page-table operations: rays.page_calls
  LinkModel link_model() const;
  // "name: unit=... box=... ..." for reports.
  std::string describe() const;
};

// The Intel iPSC/2 of the paper: 80386/80387 nodes, Direct-Connect links of
// about 2.8 MB/s, ~350 µs for a zero-byte message to a neighbour (two stages
// of 175 µs here: link and delivery). The Direct-Connect modules route in
// hardware, so that latency is NX/2 software on the two processors: each
// spends msg = 175 µs per message. Compute unit fitted to Teapot.
CostModel ipsc2_profile();

// This desktop: compute costs timed on the tracer (a small scene, divided by
// its counted operations), hop cost timed on csp channels, bandwidth by
// copying pages. Takes well under a second.
CostModel native_profile();

// A named profile ("ipsc2", "native"); std::invalid_argument for others.
CostModel profile_named(const std::string& name);

// Applies "key=value,key=value" (keys as in CostModel, values with an
// optional unit: s ms us ns ps for times, B/s KB/s MB/s GB/s for bandwidth).
// std::invalid_argument naming `where` and the bad item.
void apply_costs(CostModel& model, const std::string& spec, const std::string& where);

// A profile file: "key = value" lines (also "profile = ipsc2" as a base,
// before any cost), '#' comments, each key at most once.
// std::runtime_error "FILE:LINE: ..." for a bad line.
CostModel read_profile_file(const std::string& path);

// One processor's CPU as the meters see it: page-handler time taken from its
// pixel computers, shared out equally among them, and the virtual time until
// which the CPU is busy with a charge. A node's pixel computers share the
// one CPU: a charge runs from the later of its process's clock and the end
// of the charge before it, so their work overlaps only their waits (for
// pages and tiles), never itself.
struct NodeCpu {
  double stolen = 0;  // seconds of page handling so far
  int workers = 0;
  std::int64_t busy_until_ps = 0;
};

// Charges one pixel computer's counted work as virtual time.
class ComputeMeter {
 public:
  ComputeMeter(const CostModel& model, const tracer::RayStats& rays, std::shared_ptr<NodeCpu> cpu);
  // At the end of a tile: advances the calling process's clock by the work
  // done since the last charge, the tile's two messages and the handler
  // time stolen from this node meanwhile, run on the node's CPU after any
  // charge of another of its pixel computers still running there.
  void charge();
  // The same before a page request, with its two messages instead.
  void charge_page_request();
  double charged_seconds() const { return charged_; }

 private:
  void advance_clock();

  const CostModel& model_;
  const tracer::RayStats& rays_;
  std::shared_ptr<NodeCpu> cpu_;     // shared with the node's page server
  std::uint64_t messages_ = 0;      // sent or received so far
  double charged_ = 0;              // seconds, exact sum
  std::int64_t charged_ps_ = 0;     // what the clock has received: rounding never drifts
};

// Virtual time's observer of one node: each pixel computer's work charged
// on its own meter before each of its page requests leaves and at the end
// of each of its tiles.
class ChargingObserver final : public NodeObserver {
 public:
  explicit ChargingObserver(std::vector<ComputeMeter*> meters) : meters_(std::move(meters)) {}
  void fetch_started(int worker, std::uint32_t /*page*/) override { meter(worker).charge_page_request(); }
  void tile_done(int worker, const SvmStats& /*memory*/) override { meter(worker).charge(); }

 private:
  ComputeMeter& meter(int worker) { return *meters_.at(static_cast<std::size_t>(worker)); }
  std::vector<ComputeMeter*> meters_;  // per worker, in order
};

class MachineTiming {
 public:
  MachineTiming(CostModel model, int nodes);

  // One scheduler thread under virtual time (what makes the run deterministic).
  csp::RuntimeOptions runtime_options(std::size_t stack_size) const;
  const CostModel& model() const { return model_; }

  ComputeMeter& add_meter(int node, const tracer::RayStats& rays);
  // The observer that charges node's pixel computers, a meter for each
  // (add_meter), given their ray counters in worker order.
  std::unique_ptr<ChargingObserver> charges(int node, const std::vector<const tracer::RayStats*>& workers);
  // For node n's page server, before each reply.
  std::function<void()> serve_hook(int node);

  double predicted_seconds() const;  // after the run
  double compute_seconds() const;    // summed over the pixel computers

 private:
  CostModel model_;
  std::vector<std::shared_ptr<NodeCpu>> cpus_;  // per node
  std::vector<std::unique_ptr<ComputeMeter>> meters_;
  std::shared_ptr<csp::VirtualTimeRecord> record_;
};

}  // namespace nodes
