// The VM_pRAY machine: N processors on a topology, the scene database spread
// over them as object pages in a shared virtual memory, pixels farmed out on
// demand, everything carried by the store-and-forward network.
//
// Processes of processor n, all on the OS thread of n's router: the page
// server (Ports::page_server) and pixel computers w = 0..k-1
// (Ports::first_worker + w); on node 0 also the farmer (Ports::farmer) and
// the frame collector, fed by the farmer over a local channel. The host's
// copy of the database is moved into the owners before the run: page p lives
// only on its owner and in caches. A run ends in order, with no packet lost
// or in flight and no fiber blocked, and P (prefetch) < the network's buffer
// capacity keeps every delivery port draining. The protocol, its end and the
// buffer bounds are in docs/architecture.md: "One processor", "The path of
// one pixel", "The orderly end" and "Why the network cannot deadlock".
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nodes/machine/collector.hpp"
#include "nodes/machine/farmer.hpp"
#include "nodes/machine/node_memory.hpp"
#include "nodes/machine/node_report.hpp"
#include "nodes/machine/page_server.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "nodes/machine/pixel_order.hpp"
#include "nodes/machine/recorder.hpp"
#include "nodes/machine/svm.hpp"
#include "nodes/machine/timing.hpp"
#include "nodes/machine/work_plan.hpp"
#include "nodes/net/network.hpp"
#include "nodes/ranks/bridge.hpp"
#include "nodes/ranks/rank_plan.hpp"
#include "nodes/ranks/transport.hpp"
#include "topology/topology.hpp"
#include "tracer/database.hpp"
#include "tracer/image.hpp"
#include "tracer/render.hpp"

namespace nodes {

// How the frame's items are handed out. The defaults take each processor's
// own compact patch first: the fewest page misses and farming messages
// (the paper: dynamic, scanline, grain 4, prefetch 0).
struct Farming {
  std::uint32_t grain = 64;      // items per tile (1..max_grain): balance vs farming traffic
  std::uint16_t prefetch = 1;    // tiles a worker has asked for beyond the one it traces (..max_prefetch)
  Schedule schedule = Schedule::affinity;
  PixelOrder pixel_order = PixelOrder::hilbert;  // how items are numbered, so where a tile lies
};

// Remote pages each node caches: at most one of the two; neither, the
// default (default_cache_pages()).
struct CacheSize {
  std::optional<std::uint32_t> pages;
  std::optional<std::uint64_t> kb;  // the same in KB
};

// What a run records beside its image, for the reports and pictures.
struct Observation {
  std::uint64_t trace_routes = 0;         // record the routes of the first N packets
  std::vector<std::uint8_t> trace_kinds;  // of these MessageKinds only (empty: every kind)
  bool record_tiles = false;              // a TileSpan per tile in each NodeReport's work.spans
  bool record = false;                    // a Recording of the run for its replay (recorder.hpp); implies record_tiles
  std::uint64_t record_packets = 100000;  // with record: packets recorded hop by hop, the rest only counted
  bool tiles() const { return record_tiles || record; }  // the tiles' times are taken
};

// The OS threads that carry a run, and how the network crosses between
// them. A run takes at most one thread per node; virtual time always takes
// one (timing), and then neither relays nor in-place routing apply.
struct Threads {
  unsigned count = 0;            // 0: thread_count()'s choice; never more than the nodes
  unsigned cpus = 0;             // the CPUs count = 0 may use; 0: the host's
  bool relay_between = true;     // links between threads through relays (NetworkOptions::relay_between_threads)
  bool forward_in_place = true;  // routers of one thread route in place (NetworkOptions); real time only
  bool send_in_place = true;     // with both: routers put packets into the relays' rings (send_across_in_place)
  bool poll_rings = true;        // threads poll the relays' rings (RelayWake::poll), or are signalled
  bool shared_cores = false;     // other processes share the cores (csp::RuntimeOptions::shared_cores)
  std::optional<bool> answer_at_once;  // pixel computers answer at once (answers_at_once); none: by the rule
};

// The machine's shape beside its topology: the pixel computers on each node,
// which node owns each page, and the packets each network queue holds. The
// buffer bounds the prefetch (max_prefetch), so that the network cannot
// deadlock (docs/architecture.md).
struct Shape {
  int workers_per_node = 1;                          // 1..max_workers_per_node
  Distribution distribution = Distribution::modulo;  // page -> owner
  std::size_t buffer_capacity = 4;                   // packets per network queue
};

struct MachineOptions {
  topology::Topology topology = topology::Topology::hypercube(4);  // 16 nodes; topology::parse_topology reads a spec
  Shape shape;
  Threads threads;
  CacheSize cache;
  Farming farming;
  Observation observe;
  tracer::TraceOptions trace;
  std::optional<CostModel> timing;     // virtual time under this model (the run takes one thread)
  // For tests: the one thread's ready processes run in an order drawn from
  // this seed (csp::SeededScheduler), so one seed replays one schedule, and
  // pixel computers offer the thread every few pixels so that the draws cut
  // tiles too. Needs threads.count = 1; not with timing. A split run draws per
  // rank (csp::seed_of_stream(seed, rank)), but the wire's timing still varies.
  std::optional<std::uint64_t> schedule_seed;
  Progress progress;                   // called by the collector (on its thread): at 0 as it starts, then per result
};

// The OS threads that carry `nodes` nodes of a run: threads.count when given,
// else the CPUs, but no more than one thread for every
// min_pixel_computers_per_thread pixel computers (nodes x workers), so that
// a pixel computer waiting for a page leaves its thread another to run,
// though two threads whenever two nodes and two CPUs are there (two nodes
// on two threads, answering at once, beat one thread on every scene);
// never more than the nodes.
constexpr std::size_t min_pixel_computers_per_thread = 2;
unsigned thread_count(const MachineOptions& options, std::size_t nodes);

// Whether the pixel computers of a process that runs `local_nodes` nodes on
// `threads` threads in real time answer a packet for their thread after any
// pixel (csp::yield_to_urgent), rather than at their next page miss or
// timeslice: when a thread holds at most answer_at_once_workers of them, too
// few for the others to hide what a page request that waits there costs the
// thread that sent it. Never on one thread of a whole machine, under virtual
// time or under a schedule seed (the caller says which: `prioritised`, true
// when pixel computers run at low priority and yield at all); else
// threads.answer_at_once when set (to measure the rule), else the rule.
constexpr std::size_t answer_at_once_workers = 4;
bool answers_at_once(const MachineOptions& options, std::size_t local_nodes, unsigned threads, bool prioritised);
// Whether they also do so before every ray: when they answer at once and
// each is alone on its thread, where nothing else hides even the rest of a
// pixel (nor reads its pages meanwhile).
bool answers_between_rays(const MachineOptions& options, std::size_t local_nodes, unsigned threads, bool prioritised);

// The bounds check_options() holds the fields to: a tile of at most a
// million pixels, and at most 64 pixel computers on one node (each is a
// process with its own stack and port).
constexpr std::uint32_t max_grain = 1u << 20;
constexpr int max_workers_per_node = 64;

// The most tiles a worker may keep asked for ahead: its answers and a page
// reply must fit the network's delivery buffer (docs/architecture.md, "Why
// the network cannot deadlock").
inline std::uint16_t max_prefetch(const MachineOptions& options) {
  return static_cast<std::uint16_t>(options.shape.buffer_capacity - 1);
}

struct MachineReport {
  topology::Topology topology = topology::Topology::complete(1);  // the machine's; spec() names it
  int nodes = 0;
  unsigned threads = 0;
  int workers_per_node = 0;
  std::uint16_t prefetch = 0;
  Schedule schedule = Schedule::dynamic;
  PixelOrder pixel_order = PixelOrder::scanline;
  std::uint32_t grain = 0;
  std::uint32_t cache_pages = 0;  // requested per node (before capping at remote pages)
  std::uint32_t page_size = 0;
  std::uint32_t page_count = 0;
  std::uint64_t items = 0;  // pixels, or SPD corner samples
  double wall_seconds = 0;
  std::vector<csp::ThreadUse> host_threads;  // how each OS thread spent the run
  std::size_t relayed_links = 0;             // links between threads carried by thread relays
  std::vector<RelayCounters> relays;         // per thread, what its relay carried (empty without relays)
  std::optional<CostModel> model;            // the virtual-time model; none in real time
  double predicted_seconds = 0;    // virtual time at the end of the run
  double compute_seconds = 0;      // virtual compute time summed over the pixel computers
  std::vector<std::uint16_t> owners;  // per pixel (or corner sample), in scanline order: the node that computed it
  std::vector<NodeReport> per_node;
  FarmerCounters farmer;
  std::uint64_t collected = 0;
  NetworkStats network;
  std::vector<RankReport> ranks;  // empty unless the machine ran over several processes
  std::size_t cut_links = 0;      // links whose ends ran in different processes
  std::shared_ptr<const Recording> recording;  // with Observation::record; null otherwise

  SvmStats svm() const;
  ServerCounters served() const;
  tracer::RayStats rays() const;
  std::uint64_t items_computed() const;
  // max / mean over nodes of the items and of the rays each computed.
  double item_imbalance() const;
  double ray_imbalance() const;
  // Time the OS threads waited with no process ready, over their time (wall
  // time only: the virtual-time scheduler does not measure it).
  double idle_share() const;
};

struct MachineResult {
  tracer::Image image;
  MachineReport report;
};

// A MachineOptions field the machine cannot run with: field() is its name,
// the last part of its path in MachineOptions ("grain", "workers_per_node")
// or, for the cache, "cache_pages" or "cache_kb"; reason() what is wrong with
// its value; what() is "FIELD: REASON", one line. A caller with other names
// for the fields (command-line options) says reason() under its own.
class OptionError : public std::invalid_argument {
 public:
  OptionError(const std::string& field, const std::string& reason)
      : std::invalid_argument(field + ": " + reason), field_(field), reason_(reason) {}
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string field_, reason_;
};

// What the system would not give a machine: memory (for a process, its
// stack or the record of one) or an OS thread. what() is the runtime's own
// line; nodes() and threads() say how large the machine was, so a caller
// can say what to change.
class ResourceError : public std::runtime_error {
 public:
  enum class Resource : std::uint8_t { memory, thread };
  ResourceError(const std::string& line, Resource resource, std::size_t nodes, unsigned threads)
      : std::runtime_error(line), resource_(resource), nodes_(nodes), threads_(threads) {}
  Resource resource() const { return resource_; }
  std::size_t nodes() const { return nodes_; }
  unsigned threads() const { return threads_; }

 private:
  Resource resource_;
  std::size_t nodes_;
  unsigned threads_;
};

// Every rule of the options alone, and of the cache against pages of
// page_size bytes: OptionError naming the first field that breaks one.
// run_machine checks them before any work; a caller may check them sooner.
void check_options(const MachineOptions& options, std::uint32_t page_size);

// The cache a node gets when no size is given: 1/8 of the database, a modest
// share as in the paper's experiments, but at least 64 pages (or the whole
// database if smaller). A cache smaller than the pages one ray visits, as
// an eighth of a tiny database would be, makes nearly every access miss;
// such a cache can still be asked for by size.
std::uint32_t default_cache_pages(const tracer::DatabaseHeader& header);

// Cache size in pages from the options: OptionError naming the field for 0
// pages, less than a page of KB, or both fields set.
std::uint32_t cache_pages_for(const MachineOptions& options, const tracer::DatabaseHeader& header);

// Renders db's frame on the machine; consumes db (its pages move to their
// owners). Throws OptionError for bad options, ResourceError when the system
// has no memory or thread to give, and whatever a process throws.
MachineResult run_machine(tracer::Database db, const MachineOptions& options);

// ---- The machine split over the ranks of a Transport ----
// Every rank calls run_machine_rank with the same options; rank 0 (the
// host) passes the database and gets the result, every other rank passes
// none and gets none. Rank r runs the nodes RankPlan gives it, each rank
// holding only its own nodes' pages (rank 0 sends them) and caches; after
// the run every rank sends its reports to rank 0, whose result equals the
// one-process run's. Virtual time cannot be split (one clock orders the
// whole machine): OptionError for timing, before any work. A failure on
// any rank ends every rank's call with RankFailure, within the time it takes
// the others to notice (they poll the wire at least every millisecond); a
// rank that could not get memory or threads says so with resource().
class RankFailure : public std::runtime_error {
 public:
  RankFailure(int rank, const std::string& line)
      : std::runtime_error("rank " + std::to_string(rank) + ": " + line), rank_(rank) {}
  RankFailure(int rank, const ResourceError& shortage) : RankFailure(rank, shortage.what()) { resource_ = shortage; }
  int rank() const { return rank_; }
  // This rank's own shortage, if that is what ended it.
  const ResourceError* resource() const { return resource_ ? &*resource_ : nullptr; }

 private:
  int rank_;
  std::optional<ResourceError> resource_;
};

std::optional<MachineResult> run_machine_rank(std::optional<tracer::Database> db, const MachineOptions& options,
                                              Transport& transport);

// Rank 0, when it cannot make the database: the other ranks, waiting in
// run_machine_rank for their pages, end with RankFailure(0, why).
void abandon_machine(Transport& transport, const std::string& why);

// Route trace lines and the network summary, with the machine's kind names.
std::string format_routes(const MachineReport& report);

}  // namespace nodes
