// The VM_pRAY machine (its protocol: docs/architecture.md). A run is three
// steps, each a few functions below: build (the pages moved to their owners,
// the runtime, the network and every process on it), run (the runtime to its
// end, and what ended it in the machine's terms: ResourceError, RankFailure)
// and report (the figures, from the state the processes leave). The options
// are checked once, before the first step (check_options).
#include "nodes/machine/machine.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>

#include <sys/resource.h>

#include "csp/errors.hpp"
#include "csp/seeded_scheduler.hpp"
#include "nodes/machine/rank_clock.hpp"
#include "nodes/machine/report_wire.hpp"
#include "nodes/net/mailbox.hpp"
#include "topology/spec.hpp"
#include "tracer/huge_pages.hpp"

namespace nodes {

namespace {

// Everything one processor holds during a run; addresses stay stable while
// its processes refer to them.
struct NodeState {
  std::unique_ptr<NodeSvm> svm;
  ServerCounters served;
  std::unique_ptr<PageServer> server;
  std::vector<std::unique_ptr<Outbox>> worker_out;
  std::vector<std::unique_ptr<WorkerPort>> worker_in;
  std::vector<WorkerCounters> work;
  std::unique_ptr<NodeObserver> observer;  // null unless virtual time or the recorder watches
  std::unique_ptr<Mailbox> mailbox;
};

// Node 0's extra processes and what they fill in.
struct Host {
  std::unique_ptr<WorkPlan> plan;
  std::unique_ptr<FrameAssembler> frame;
  std::unique_ptr<Mailbox> mailbox;
  std::unique_ptr<csp::Channel<Packet>> results;  // farmer -> collector
  FarmerCounters farmer;
  std::vector<std::uint16_t> owners;  // per pixel or corner sample in scanline order, filled by the collector
};

std::unique_ptr<NodeState> node_state(NodeMemory memory) {
  auto state = std::make_unique<NodeState>();
  state->svm = std::make_unique<NodeSvm>(std::move(memory));
  return state;
}

// The rules of the fields that need no database.
void check_fields(const MachineOptions& options) {
  const auto within = [](const char* field, std::int64_t value, std::int64_t hi) {
    if (value < 1) throw OptionError(field, "must be at least 1, got " + std::to_string(value));
    if (value > hi) throw OptionError(field, "must be at most " + std::to_string(hi) + ", got " + std::to_string(value));
  };
  within("workers_per_node", options.shape.workers_per_node, max_workers_per_node);
  within("grain", options.farming.grain, max_grain);
  within("buffer_capacity", static_cast<std::int64_t>(std::min<std::size_t>(options.shape.buffer_capacity, INT64_MAX)),
         INT64_MAX);
  if (options.schedule_seed && options.timing)
    throw OptionError("schedule_seed", "cannot be given with timing (virtual time orders the processes by its clock)");
  if (options.schedule_seed && options.threads.count != 1)
    throw OptionError("schedule_seed", "needs threads = 1 (a seed replays its schedule on one thread only), got " +
                                           std::to_string(options.threads.count));
  if (options.farming.prefetch > max_prefetch(options))
    throw OptionError("prefetch", "must be at most " + std::to_string(max_prefetch(options)) + ", got " +
                                      std::to_string(options.farming.prefetch) +
                                      " (a worker's answers and a page reply must fit the network buffer of " +
                                      std::to_string(options.shape.buffer_capacity) + " packets)");
}

// Moves each page from the host's database into its owner's memory, in
// page order, each freed once placed and the freed memory given back every
// few megabytes: the pages of a database, allocated in that order, are
// then held about once, not by the host and the nodes at the same time.
std::vector<std::unique_ptr<NodeState>> distribute(tracer::Database& db, const PagePlacement& placement,
                                                   std::uint32_t cache_pages) {
  std::vector<std::unique_ptr<NodeState>> nodes;
  for (int n = 0; n < placement.nodes(); ++n)
    nodes.push_back(node_state(NodeMemory(placement, n, db.header.page_size, cache_pages)));
  constexpr std::uint32_t pages_per_return = 4096;
  for (std::uint32_t p = 0; p < db.pages.size(); ++p) {
    nodes[static_cast<std::size_t>(placement.owner(p))]->svm->memory().place_own(placement.own_index(p), db.pages[p]);
    std::vector<std::byte>().swap(db.pages[p]);
    if ((p + 1) % pages_per_return == 0) tracer::return_freed_heap();
  }
  db.pages.clear();
  db.pages.shrink_to_fit();  // the host keeps no copy
  tracer::return_freed_heap();
  return nodes;
}

// Results the farmer may pass on before the collector runs.
constexpr std::size_t results_buffer = 16;

// Pixels a pixel computer traces between two yields: some tens of
// microseconds of tracing for one context switch.
constexpr std::uint32_t timeslice_items = 16;
// The same under a schedule seed: short, so that small tiles are cut too.
constexpr std::uint32_t seeded_timeslice_items = 3;

struct Wiring {
  csp::Runtime& runtime;
  Network& net;
  const PagePlacement& placement;
  const tracer::DatabaseHeader& header;
  const MachineOptions& options;
  ItemGrid grid;
  std::uint64_t processes;  // sending processes, for packet ids
  MachineTiming* timing;    // null unless in virtual time
  RunClock tile_clock;      // empty unless tiles are recorded
  Recorder* recorder;       // null unless the run is recorded for its replay
  bool split = false;       // other processes run the other nodes (a bridge serves the wire)
  std::size_t local_nodes = 0;  // nodes this process runs

  Outbox outbox(NodeId n, std::uint16_t port) const {
    const std::uint64_t ports = Ports::count(options.shape.workers_per_node);
    return Outbox(net.in_place_injector(n, port), n * ports + port, processes);
  }
};

// The packets the protocol lets be outstanding (docs/architecture.md, "Why
// the network cannot deadlock"): for a page
// server, one request per sending process of the machine and its
// server_stop; for the farmer, P + 1 per worker and one per page server.
std::size_t page_requests_bound(std::size_t nodes, int workers_per_node) {
  return nodes * Ports::count(workers_per_node) + 1;
}
std::size_t farmer_bound(std::size_t nodes, int workers_per_node, std::uint16_t prefetch) {
  return nodes * static_cast<std::size_t>(workers_per_node) * (prefetch + 1u) + nodes;
}

// What the page server or the farmer (port) of node n reads: the delivery
// port itself, sized to its bound (network_options), or with a link model
// (delivery by rendezvous) a mailbox of that size, kept in `mailbox`
// (channel "WHO requests", process "WHO mailbox").
csp::In<Packet> drained_port(const Wiring& w, NodeId n, std::uint16_t port, std::size_t bound,
                             const std::string& who, std::unique_ptr<Mailbox>& mailbox) {
  if (!w.net.options().link.enabled()) return w.net.port(n, port);
  mailbox = std::make_unique<Mailbox>(who + " requests", bound);
  w.runtime.spawn(who + " mailbox", w.net.thread_of(n),
                  [mb = mailbox.get(), in = w.net.port(n, port)] { mb->forward(in); });
  return mailbox->reader();
}

// Who watches node n's pixel computers: virtual time's charges, then the
// recorder, so that a recorded wait starts as its request leaves, after the
// work before it is charged; null when neither watches.
std::unique_ptr<NodeObserver> node_observer(const Wiring& w, NodeId n, const std::vector<WorkerCounters>& work) {
  auto observers = std::make_unique<ObserverList>();
  if (w.timing) {
    std::vector<const tracer::RayStats*> rays;
    for (const WorkerCounters& counters : work) rays.push_back(&counters.rays);
    observers->add(w.timing->charges(static_cast<int>(n), rays));
  }
  if (w.recorder) observers->add(std::make_unique<RecordingObserver>(*w.recorder, n, static_cast<int>(work.size())));
  if (observers->empty()) return nullptr;
  return observers;
}

// Whether pixel computers run at low priority, yielding every few pixels.
// On the one thread of a whole machine nobody waits across threads or
// processes, and first-in first-out order lets a router take more packets
// per wake-up; under virtual time the scheduler orders by clock. A split
// machine's bridge polls the wire and needs the thread often.
bool prioritised(const Wiring& w) { return !w.timing && (w.runtime.threads() > 1 || w.split); }

// How pixel computers pace their work. Under a schedule seed they yield
// every few pixels whatever their priority, so that the seeded draws also
// interleave them mid-tile.
WorkerPacing worker_pacing(const Wiring& w, NodeObserver* observer) {
  const std::uint32_t timeslice = w.options.schedule_seed ? seeded_timeslice_items
                                  : prioritised(w)        ? timeslice_items
                                                          : 0;
  const unsigned threads = w.runtime.threads();
  return {w.options.farming.prefetch,
          timeslice,
          answers_at_once(w.options, w.local_nodes, threads, prioritised(w)),
          answers_between_rays(w.options, w.local_nodes, threads, prioritised(w)),
          observer,
          w.tile_clock};
}

void spawn_node(const Wiring& w, NodeId n, NodeState& node) {
  const unsigned thread = w.net.thread_of(n);
  const std::string name = "node " + std::to_string(n);
  const int k = w.options.shape.workers_per_node;
  const csp::In<Packet> requests =
      drained_port(w, n, Ports::page_server, page_requests_bound(w.net.topology().size(), k), name + " page",
                   node.mailbox);
  std::function<void()> serve_hook = w.timing ? w.timing->serve_hook(static_cast<int>(n)) : nullptr;
  node.server = std::make_unique<PageServer>(n, node.svm->memory(), requests, w.outbox(n, Ports::page_server),
                                             node.served, serve_hook, w.recorder);
  w.net.receive_in_place(n, Ports::page_server, *node.server);
  w.runtime.spawn(name + " page server", thread, [server = node.server.get()] { server->run(); });
  node.work.resize(static_cast<std::size_t>(k));
  node.observer = node_observer(w, n, node.work);
  const TraceWork work{w.header, w.options.trace, w.grid};
  const WorkerPacing pacing = worker_pacing(w, node.observer.get());
  for (int i = 0; i < k; ++i) {
    const auto port = static_cast<std::uint16_t>(Ports::first_worker + i);
    Outbox& out = *node.worker_out.emplace_back(std::make_unique<Outbox>(w.outbox(n, port)));
    WorkerPort& in = *node.worker_in.emplace_back(std::make_unique<WorkerPort>(w.net.port(n, port)));
    SvmSource& source = node.svm->add_worker(make_page_fetch(w.placement, port, in, out, node.observer.get()));
    const WorkerLinks links{port, source, in, out, node.work[static_cast<std::size_t>(i)]};
    w.runtime.spawn(
        name + " pixel computer " + std::to_string(i), thread,
        [work, links, pacing] { PixelComputer(work, links, pacing).run(); },
        prioritised(w) ? csp::Priority::low : csp::Priority::high);
  }
}

void spawn_host(const Wiring& w, Host& host) {
  const unsigned thread = w.net.thread_of(0);
  const auto nodes = static_cast<std::size_t>(w.net.topology().size());
  const csp::In<Packet> requests = drained_port(
      w, 0, Ports::farmer, farmer_bound(nodes, w.options.shape.workers_per_node, w.options.farming.prefetch), "farmer",
      host.mailbox);
  host.results = std::make_unique<csp::Channel<Packet>>("results", results_buffer);
  w.runtime.spawn("farmer", thread, [&w, &host, nodes, requests, out = w.outbox(0, Ports::farmer)] {
    Farmer(*host.plan, static_cast<int>(nodes), w.options.shape.workers_per_node, requests, out,
           host.results->writer(), [&net = w.net] { net.shutdown(); }, host.farmer)
        .run();
  });
  w.runtime.spawn("collector", thread, [&w, &host] {
    Collector(*host.frame, host.results->reader(), w.options.progress, &host.owners).run();
  });
}

// items: every pixel or corner sample, in scanline order.
tracer::Image assemble_image(const tracer::DatabaseHeader& header, const ItemGrid& grid,
                             std::vector<tracer::Color>&& items) {
  const int width = header.camera.width, height = header.camera.height;
  if (!grid.corners) return tracer::Image(width, height, std::move(items));  // items are the pixels, in rows
  tracer::Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const auto at = [&](int sx, int sy) { return items[static_cast<std::size_t>(sy) * grid.width + sx]; };
      image.at(x, y) = tracer::Tracer::average_corners(at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1));
    }
  return image;
}

NodeReport node_report(const NodeState& node) {
  NodeReport r;
  r.svm = node.svm->stats();
  r.served = node.served;
  for (const auto& w : node.work) {
    r.work.items += w.items;
    r.work.tiles += w.tiles;
    r.work.rays += w.rays;
    r.work.spans.insert(r.work.spans.end(), w.spans.begin(), w.spans.end());
  }
  const NodeMemory& memory = node.svm->memory();
  r.own_bytes = memory.own_bytes();
  r.peak_resident_bytes = memory.resident_bytes();  // slots are never freed during a run
  r.cache_capacity = memory.cache_capacity();
  r.evictions = memory.evictions();
  return r;
}

// Seconds since `started` on the wall clock, or the calling process's virtual clock.
RunClock run_clock(std::chrono::steady_clock::time_point started, bool virtual_time) {
  if (virtual_time) return [] { return std::chrono::duration<double>(csp::this_process::now()).count(); };
  return [started] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(); };
}

double imbalance(const std::vector<double>& values) {
  if (values.empty()) return 1.0;
  double sum = 0, max = 0;
  for (double v : values) {
    sum += v;
    max = std::max(max, v);
  }
  return sum > 0 ? max / (sum / static_cast<double>(values.size())) : 1.0;
}

// The pixel computers of `nodes` nodes.
std::size_t pixel_computers(const MachineOptions& options, std::size_t nodes) {
  return nodes * static_cast<std::size_t>(std::max(options.shape.workers_per_node, 1));
}

}  // namespace

unsigned thread_count(const MachineOptions& options, std::size_t nodes) {
  nodes = std::max<std::size_t>(nodes, 1);
  if (options.threads.count) return static_cast<unsigned>(std::min<std::size_t>(options.threads.count, nodes));
  const std::size_t cpus =
      options.threads.cpus ? options.threads.cpus : std::max(1u, std::thread::hardware_concurrency());
  const std::size_t by_workers =
      std::max<std::size_t>(pixel_computers(options, nodes) / min_pixel_computers_per_thread, 2);
  return static_cast<unsigned>(std::min({cpus, by_workers, nodes}));
}

// Rings4 on two threads, 2 to 8 nodes (1 to 4 pixel computers a thread):
// 10-20% faster answering at once; 16 and 64 nodes (8 and 32 a thread): up
// to 5% slower, the switches costing more than the wait they save.
bool answers_at_once(const MachineOptions& options, std::size_t local_nodes, unsigned threads, bool prioritised) {
  if (!prioritised || options.schedule_seed) return false;
  if (options.threads.answer_at_once) return *options.threads.answer_at_once;
  return pixel_computers(options, local_nodes) <= answer_at_once_workers * std::max(threads, 1u);
}

// Rings4 on two threads, medians of 9 and 11 alternating runs: 2 nodes 0.414
// -> 0.369 s answering before every ray too, 4 nodes unchanged, 8 nodes
// 0.395 -> 0.409 s.
bool answers_between_rays(const MachineOptions& options, std::size_t local_nodes, unsigned threads, bool prioritised) {
  return answers_at_once(options, local_nodes, threads, prioritised) &&
         pixel_computers(options, local_nodes) <= std::max(threads, 1u);
}

std::uint32_t default_cache_pages(const tracer::DatabaseHeader& header) {
  constexpr std::uint32_t share = 8, floor_pages = 64;
  return std::max({std::uint32_t{1}, header.page_count / share, std::min(header.page_count, floor_pages)});
}

namespace {

// The cache asked for, in pages of page_size bytes; none when neither field is set.
std::optional<std::uint32_t> asked_cache_pages(const MachineOptions& options, std::uint32_t page_size) {
  if (options.cache.pages && options.cache.kb)
    throw OptionError("cache_kb", "given with the cache in pages: give one of them, not both");
  if (options.cache.pages) {
    if (*options.cache.pages == 0) throw OptionError("cache_pages", "must be at least 1, got 0");
    return *options.cache.pages;
  }
  if (!options.cache.kb) return std::nullopt;
  const std::uint64_t pages = *options.cache.kb * 1024 / page_size;
  if (pages == 0)
    throw OptionError("cache_kb", std::to_string(*options.cache.kb) + " KB is less than one page (" +
                                      std::to_string(page_size) + " bytes)");
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(pages, UINT32_MAX));
}

}  // namespace

void check_options(const MachineOptions& options, std::uint32_t page_size) {
  check_fields(options);
  asked_cache_pages(options, page_size);
}

std::uint32_t cache_pages_for(const MachineOptions& options, const tracer::DatabaseHeader& header) {
  return asked_cache_pages(options, header.page_size).value_or(default_cache_pages(header));
}

namespace {

// Which nodes this process runs: all of them, or one rank's block.
struct Share {
  const RankPlan* plan = nullptr;  // null: the whole machine
  Transport* transport = nullptr;
  int rank = 0;

  bool runs(NodeId n) const { return plan == nullptr || plan->runs(rank, n); }
  std::size_t node_count(std::size_t nodes) const { return plan ? plan->count(rank) : nodes; }
  NodeId first_node() const { return plan ? plan->first(rank) : 0; }
};

// What a split run adds to the processes: the bridge and its notes.
struct SplitState {
  FailureNote local_failure, remote_failure;
  BridgeCounters bridge;
};

double cpu_seconds() {
  rusage use{};
  getrusage(RUSAGE_SELF, &use);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(use.ru_utime) + seconds(use.ru_stime);
}

// ---- Build: the runtime, the network and every process on them ----

// The runtime of this process's nodes. In a split run a process that fails
// leaves others waiting on it, and the bridge polling the wire keeps the
// runtime from calling that a deadlock: the failure is noted for the other
// ranks and the network shut down (once it exists), so the bridge tells
// them and ends.
csp::RuntimeOptions runtime_options(const MachineOptions& options, std::size_t local_nodes, const MachineTiming* timing,
                                    SplitState* split, int rank, Network* const& network) {
  csp::RuntimeOptions r;
  r.threads = thread_count(options, local_nodes);
  r.shared_cores = options.threads.shared_cores;
  if (timing) r = timing->runtime_options(r.stack_size);
  if (options.schedule_seed) r.scheduler = csp::seeded_scheduler(csp::seed_of_stream(*options.schedule_seed, rank));
  if (split)
    r.on_failure = [split, &network, rank](const std::string& process, std::exception_ptr error) {
      split->local_failure.set(rank, "process '" + process + "' failed: " + csp::message_of(error));
      if (network) network->shutdown();
    };
  return r;
}

NetworkOptions network_options(const MachineOptions& options, const MachineTiming* timing, const Share& share,
                               std::size_t topology_size, std::size_t local_nodes, unsigned threads,
                               Recorder* recorder) {
  NetworkOptions net;
  net.buffer_capacity = options.shape.buffer_capacity;
  net.ports_per_node = Ports::count(options.shape.workers_per_node);
  net.trace_routes = options.observe.trace_routes;
  net.trace_kinds = options.observe.trace_kinds;
  net.recorder = recorder;
  if (timing) net.link = timing->model().link_model();
  if (!net.link.enabled()) {
    // The page servers and the farmer read their ports directly (spawn_node, spawn_host).
    const std::size_t nodes = topology_size;
    net.port_capacity.assign(Ports::first_worker, 0);
    net.port_capacity[Ports::page_server] = page_requests_bound(nodes, options.shape.workers_per_node);
    net.port_capacity[Ports::farmer] = farmer_bound(nodes, options.shape.workers_per_node, options.farming.prefetch);
  }
  net.relay_between_threads = options.threads.relay_between && !timing;
  net.forward_in_place = options.threads.forward_in_place && !timing;
  net.send_across_in_place = options.threads.send_in_place && net.relay_between_threads && net.forward_in_place;
  net.relay_wake = options.threads.poll_rings ? RelayWake::poll : RelayWake::signal;
  if (share.plan) {
    net.local = [share](NodeId n) { return share.runs(n); };
    net.placement = [first = share.first_node(), local_nodes, threads](NodeId n) {
      return Network::block_placement(n - first, local_nodes, threads);
    };
  }
  return net;
}

// What the farmer hands out: every pixel, or with the SPD procedure every
// pixel corner, numbered in the pixel order. grid.positions points into
// positions, so an Items stays where it was made.
struct Items {
  std::vector<std::uint32_t> positions;
  ItemGrid grid;
  std::uint32_t count = 0;

  Items(const tracer::DatabaseHeader& header, const MachineOptions& options) {
    const bool corners = options.trace.spd_procedure;
    const int rows = header.camera.height + (corners ? 1 : 0);
    grid = {header.camera.width + (corners ? 1 : 0), corners, {}};
    positions = item_positions(grid.width, rows, options.farming.pixel_order);
    grid.positions = positions;
    count = static_cast<std::uint32_t>(grid.width) * static_cast<std::uint32_t>(rows);
  }
  Items(const Items&) = delete;
  Items& operator=(const Items&) = delete;
};

// Spawns the processes of every node this process runs, node 0's farmer and
// collector if it runs node 0, and a split run's bridge.
void spawn_machine(const Wiring& wiring, std::vector<std::unique_ptr<NodeState>>& nodes, const Items& items,
                   const Share& share, SplitState* split, Host& host, std::unique_ptr<Bridge>& bridge) {
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n]) spawn_node(wiring, static_cast<NodeId>(n), *nodes[n]);
  if (share.runs(0)) {
    const MachineOptions& options = wiring.options;
    host.plan =
        std::make_unique<WorkPlan>(items.count, options.farming.grain, options.farming.schedule,
                                   static_cast<int>(wiring.net.topology().size()), options.shape.workers_per_node);
    host.frame = std::make_unique<FrameAssembler>(items.count, items.grid.positions);
    host.owners.assign(items.count, 0);
    spawn_host(wiring, host);
  }
  if (share.plan) {
    bridge = std::make_unique<Bridge>(*share.transport, *share.plan, wiring.net, split->local_failure,
                                      split->remote_failure, split->bridge);
    wiring.runtime.spawn("bridge", wiring.net.thread_of(share.first_node()), [&bridge] { bridge->run(); });
  }
}

// ---- Run: the runtime to its end, its failures in the machine's terms ----

// Runs the runtime. What the system would not give becomes a ResourceError
// sized by the machine; in a split run every failure becomes a RankFailure,
// this rank's own first (what else ended here followed from it).
void run_and_translate(csp::Runtime& runtime, std::size_t nodes, SplitState* split, int rank) {
  using Resource = ResourceError::Resource;
  const auto shortage = [&](const std::string& line, Resource resource) {
    return ResourceError(line, resource, nodes, runtime.threads());
  };
  try {
    try {
      runtime.run();
    } catch (const csp::ThreadNotStarted& e) {
      throw shortage(e.what(), Resource::thread);
    } catch (const csp::ProcessNotStarted& e) {
      throw shortage(e.what(), Resource::memory);
    } catch (const std::bad_alloc&) {
      throw shortage("a process of the machine ran out of memory", Resource::memory);
    } catch (const csp::ProcessesFailed& e) {
      if (!e.out_of_memory()) throw;
      throw shortage(e.what(), Resource::memory);
    }
  } catch (const std::exception& e) {
    if (split == nullptr) throw;
    if (const auto local = split->local_failure.get()) throw RankFailure(local->first, local->second);
    if (const auto remote = split->remote_failure.get()) throw RankFailure(remote->first, remote->second);
    if (const auto* resource = dynamic_cast<const ResourceError*>(&e)) throw RankFailure(rank, *resource);
    throw RankFailure(rank, e.what());
  }
  if (split == nullptr) return;
  if (const auto remote = split->remote_failure.get()) throw RankFailure(remote->first, remote->second);
}

// ---- Report: what the run did, from the state it leaves ----

struct Executed {
  MachineResult result;
  std::vector<RouterCounters> routers;  // split runs only: index = node, zero for other ranks' nodes
  std::unique_ptr<Recorder> recorder;   // recorded split runs only: this rank's logs, merged on rank 0
};

// The figures of the machine as this process ran it; per_node entries of
// nodes it did not run stay empty.
MachineReport machine_report(const csp::Runtime& runtime, const Network& net, const MachineTiming* timing,
                             const tracer::DatabaseHeader& header, const MachineOptions& options,
                             std::uint32_t cache_pages, std::uint32_t items,
                             const std::vector<std::unique_ptr<NodeState>>& nodes) {
  MachineReport report;
  report.topology = net.topology();
  report.nodes = static_cast<int>(net.topology().size());
  report.threads = runtime.threads();
  report.workers_per_node = options.shape.workers_per_node;
  report.prefetch = options.farming.prefetch;
  report.schedule = options.farming.schedule;
  report.pixel_order = options.farming.pixel_order;
  report.grain = options.farming.grain;
  report.cache_pages = cache_pages;
  report.page_size = header.page_size;
  report.page_count = header.page_count;
  report.items = items;
  report.host_threads = runtime.thread_use();
  report.relayed_links = net.relayed_links();
  if (report.relayed_links > 0)
    for (unsigned t = 0; t < runtime.threads(); ++t) report.relays.push_back(net.relay_counters(t));
  if (timing) {
    report.model = timing->model();
    report.predicted_seconds = timing->predicted_seconds();
    report.compute_seconds = timing->compute_seconds();
  }
  report.per_node.resize(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n]) report.per_node[n] = node_report(*nodes[n]);
  report.network = net.stats();
  return report;
}

// A split run's rank: what it ran and what crossed its wire.
RankReport rank_report(const Share& share, std::size_t local_nodes, unsigned threads, const SplitState& split,
                       const MachineReport& report, double cpu_seconds_used) {
  RankReport rank;
  rank.rank = share.rank;
  rank.first_node = share.first_node();
  rank.node_count = static_cast<std::uint32_t>(local_nodes);
  rank.threads = threads;
  rank.bridge = split.bridge;
  rank.wall_seconds = report.wall_seconds;
  rank.cpu_seconds = cpu_seconds_used;
  for (NodeId n = share.first_node(); n < share.first_node() + local_nodes; ++n)
    rank.peak_scene_bytes += report.per_node[n].peak_resident_bytes;
  return rank;
}

// The run of this process's share of the machine: build, run, report.
// nodes[n] is null for the nodes another process runs; the result's
// per_node entries for those stay empty and its image is empty unless this
// process runs node 0.
// The run's recording: the nodes' logs merged, with each node's tiles.
std::shared_ptr<const Recording> recording_of(const Recorder& recorder, const topology::Topology& topology,
                                              const MachineReport& report) {
  std::vector<std::vector<TileSpan>> tiles;
  for (const NodeReport& n : report.per_node) tiles.push_back(n.work.spans);
  return std::make_shared<const Recording>(merge_recording(recorder, topology, std::move(tiles)));
}

// What a rank of a split run adds to its report: its own figures and the
// cut links; the routers' counters travel to rank 0 with the node reports.
void add_rank_figures(Executed& executed, const Share& share, std::size_t local_nodes, unsigned threads,
                      const SplitState& split, const Network& net,
                      const std::vector<std::unique_ptr<NodeState>>& nodes, double cpu) {
  MachineReport& report = executed.result.report;
  report.ranks.push_back(rank_report(share, local_nodes, threads, split, report, cpu));
  report.cut_links = share.plan->cut_links();
  executed.routers.resize(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n]) executed.routers[n] = net.router_counters(static_cast<NodeId>(n));
}

Executed execute(const tracer::DatabaseHeader& header, const topology::Topology& topology,
                 const PagePlacement& placement, std::uint32_t cache_pages,
                 std::vector<std::unique_ptr<NodeState>>& nodes, const MachineOptions& options, const Share& share) {
  const auto started = std::chrono::steady_clock::now();
  const double cpu_started = cpu_seconds();
  std::optional<MachineTiming> virtual_time;
  if (options.timing) virtual_time.emplace(*options.timing, static_cast<int>(topology.size()));
  MachineTiming* const timing = virtual_time ? &*virtual_time : nullptr;
  const std::size_t local_nodes = share.node_count(topology.size());
  std::optional<SplitState> split_state;
  if (share.plan) split_state.emplace();
  SplitState* const split = split_state ? &*split_state : nullptr;

  Network* network = nullptr;  // for the runtime's failure handler, once it exists
  csp::Runtime runtime(runtime_options(options, local_nodes, timing, split, share.rank, network));
  // Over several ranks each records its share of the packets, on its own clock.
  const std::uint64_t packets = options.observe.record_packets;
  const std::uint64_t budget = share.plan ? rank_budget(packets, share.plan->ranks(), share.rank) : packets;
  std::unique_ptr<Recorder> recorder =
      options.observe.record ? std::make_unique<Recorder>(topology.size(), budget, timing != nullptr, started) : nullptr;
  Network net(runtime, topology,
              network_options(options, timing, share, topology.size(), local_nodes, runtime.threads(), recorder.get()));
  network = &net;
  const Items items(header, options);
  const Wiring wiring{runtime,
                      net,
                      placement,
                      header,
                      options,
                      items.grid,
                      topology.size() * Ports::count(options.shape.workers_per_node),
                      timing,
                      options.observe.tiles() ? run_clock(started, timing != nullptr) : RunClock{},
                      recorder.get(),
                      split != nullptr,
                      local_nodes};
  Host host;
  std::unique_ptr<Bridge> bridge;
  spawn_machine(wiring, nodes, items, share, split, host, bridge);

  run_and_translate(runtime, topology.size(), split, share.rank);
  const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  Executed executed;
  MachineReport& report = executed.result.report;
  report = machine_report(runtime, net, timing, header, options, cache_pages, items.count, nodes);
  report.wall_seconds = wall_seconds;
  if (recorder && !split) report.recording = recording_of(*recorder, topology, report);
  if (split)
    add_rank_figures(executed, share, local_nodes, runtime.threads(), *split, net, nodes, cpu_seconds() - cpu_started);
  executed.recorder = split ? std::move(recorder) : nullptr;
  if (share.runs(0)) {
    report.farmer = host.farmer;
    report.farmer.steals = host.plan->steals();
    report.collected = host.frame->received();
    report.owners = std::move(host.owners);
    executed.result.image = assemble_image(header, items.grid, host.frame->take_colors());
  }
  return executed;
}

}  // namespace

MachineResult run_machine(tracer::Database db, const MachineOptions& options) {
  check_options(options, db.header.page_size);
  const topology::Topology& topology = options.topology;
  const std::uint32_t cache_pages = cache_pages_for(options, db.header);
  const PagePlacement placement(options.shape.distribution, static_cast<int>(topology.size()), db.header.page_count);
  auto nodes = distribute(db, placement, cache_pages);
  return execute(db.header, topology, placement, cache_pages, nodes, options, Share{}).result;
}

namespace {

enum class Setup : std::uint8_t { failed = 0, ok = 1 };

// Rank 0: the header to every rank, then each node's own pages, end to end,
// to the rank that runs it, one node at a time, so that the host holds at
// most one node's share twice. Keeps its own nodes' pages.
void send_setup(tracer::Database& db, const RankPlan& plan, const PagePlacement& placement,
                std::uint32_t cache_pages, Transport& transport, std::vector<std::unique_ptr<NodeState>>& nodes) {
  for (int q = 1; q < plan.ranks(); ++q) {
    WireWriter w;
    w.put(Setup::ok);
    put_header(w, db.header);
    w.put(cache_pages);
    transport.post(q, Tag::setup, w.take());
  }
  const std::size_t page_size = db.header.page_size;
  for (NodeId n = 0; n < plan.nodes(); ++n) {
    const int owner = static_cast<int>(n);
    const std::uint32_t own = placement.own_count(owner);
    if (plan.runs(0, n)) {
      NodeMemory memory(placement, owner, page_size, cache_pages);
      for (std::uint32_t i = 0; i < own; ++i) {
        auto& page = db.pages[placement.page_of(owner, i)];
        memory.place_own(i, page);
        std::vector<std::byte>().swap(page);
      }
      nodes[n] = node_state(std::move(memory));
      continue;
    }
    Bytes share;
    share.reserve(std::size_t{own} * page_size);
    for (std::uint32_t i = 0; i < own; ++i) {
      auto& page = db.pages[placement.page_of(owner, i)];
      share.insert(share.end(), page.begin(), page.end());
      std::vector<std::byte>().swap(page);
    }
    transport.post(plan.rank_of(n), Tag::setup, std::move(share));
    transport.flush();
  }
  db.pages.clear();
  db.pages.shrink_to_fit();
}

// Any other rank: the header and its own nodes' pages from rank 0.
tracer::DatabaseHeader receive_setup(const MachineOptions& options, const RankPlan& plan, int rank,
                                     Transport& transport, std::vector<std::unique_ptr<NodeState>>& nodes) {
  const Incoming first = transport.receive(Tag::setup, 0);
  WireReader r(first.bytes);
  if (r.get<Setup>() != Setup::ok) throw RankFailure(0, r.get_string());
  tracer::DatabaseHeader header = get_header(r);
  const auto cache_pages = r.get<std::uint32_t>();
  const PagePlacement placement(options.shape.distribution, static_cast<int>(plan.nodes()), header.page_count);
  for (NodeId n = plan.first(rank); n < plan.first(rank) + plan.count(rank); ++n) {
    const Incoming share = transport.receive(Tag::setup, 0);
    const std::uint32_t own = placement.own_count(static_cast<int>(n));
    if (share.bytes.size() != std::size_t{own} * header.page_size)
      throw std::runtime_error("node " + std::to_string(n) + ": rank 0 sent " + std::to_string(share.bytes.size()) +
                               " bytes of pages, not " + std::to_string(own) + " pages");
    NodeMemory memory(placement, static_cast<int>(n), header.page_size, cache_pages);
    for (std::uint32_t i = 0; i < own; ++i)
      memory.place_own(i, std::span(share.bytes.data() + std::size_t{i} * header.page_size, header.page_size));
    nodes[n] = node_state(std::move(memory));
  }
  return header;
}

// Another rank's part of the reports: its own, its nodes' and routers', and
// in a recorded run its nodes' logs, then its clock for rank 0 to read.
void report_to_rank_zero(Transport& transport, const RankPlan& plan, int rank, const Executed& executed) {
  const MachineReport& report = executed.result.report;
  WireWriter w;
  put_rank_report(w, report.ranks.front(), report.host_threads);
  for (NodeId n = plan.first(rank); n < plan.first(rank) + plan.count(rank); ++n) {
    put_node_report(w, report.per_node[n]);
    put_router_counters(w, executed.routers[n]);
    if (executed.recorder) put_node_log(w, executed.recorder->log(n));
  }
  transport.post(0, Tag::report, w.take());
  transport.flush();
  if (executed.recorder) answer_clock(transport, *executed.recorder);
}

// Rank 0 folds another rank's reports into its own (and, in a recorded
// run, its nodes' logs into `recorder`, still on that rank's clock).
void merge_rank(const Incoming& message, const RankPlan& plan, MachineReport& report,
                std::vector<RouterCounters>& routers, Recorder* recorder) {
  WireReader r(message.bytes);
  std::vector<csp::ThreadUse> threads;
  report.ranks.push_back(get_rank_report(r, threads));
  report.host_threads.insert(report.host_threads.end(), threads.begin(), threads.end());
  for (NodeId n = plan.first(message.from); n < plan.first(message.from) + plan.count(message.from); ++n) {
    report.per_node[n] = get_node_report(r);
    routers[n] = get_router_counters(r);
    if (recorder) recorder->adopt(n, get_node_log(r));
  }
  if (!r.done()) throw std::runtime_error("rank " + std::to_string(message.from) + " sent a report too long");
}

// Rank 0, in a recorded split run, once every rank has reported: each
// rank's logs and tiles moved onto rank 0's clock, and merged.
std::shared_ptr<const Recording> split_recording(Transport& transport, const RankPlan& plan,
                                                 const topology::Topology& topology, MachineReport& report,
                                                 Recorder& recorder, std::uint64_t packets) {
  std::vector<int> node_rank(topology.size(), 0);
  for (int q = 1; q < plan.ranks(); ++q) {
    const double offset = clock_offset(transport, q, recorder).offset;
    for (NodeId n = plan.first(q); n < plan.first(q) + plan.count(q); ++n) {
      node_rank[n] = q;
      shift_times(recorder.log(n), offset);
      for (TileSpan& span : report.per_node[n].work.spans) span.start += offset, span.end += offset;
    }
  }
  std::vector<std::vector<TileSpan>> tiles;
  for (const NodeReport& n : report.per_node) tiles.push_back(n.work.spans);
  Recording recording = merge_recording(recorder, topology, std::move(tiles), std::move(node_rank));
  recording.max_packets = packets;
  return std::make_shared<const Recording>(std::move(recording));
}

}  // namespace

void abandon_machine(Transport& transport, const std::string& why) {
  for (int q = 1; q < transport.size(); ++q) {
    WireWriter w;
    w.put(Setup::failed);
    w.put_string(why);
    transport.post(q, Tag::setup, w.take());
  }
  transport.flush();
}

std::optional<MachineResult> run_machine_rank(std::optional<tracer::Database> db, const MachineOptions& options,
                                              Transport& transport) {
  const int rank = transport.rank();
  if ((rank == 0) != db.has_value())
    throw std::logic_error("run_machine_rank: rank 0, and only rank 0, holds the database");
  // The same options on every rank: these fail on all of them alike.
  check_fields(options);
  if (options.timing)
    throw OptionError("timing", "virtual time cannot run over several processes (one clock orders the machine)");
  const topology::Topology& topology = options.topology;
  const RankPlan plan(topology, transport.size());
  std::vector<std::unique_ptr<NodeState>> nodes(topology.size());
  tracer::DatabaseHeader header;
  std::uint32_t cache_pages = 0;
  if (rank == 0) {
    try {
      cache_pages = cache_pages_for(options, db->header);
      const PagePlacement placement(options.shape.distribution, static_cast<int>(topology.size()),
                                    db->header.page_count);
      send_setup(*db, plan, placement, cache_pages, transport, nodes);
    } catch (const std::exception& e) {
      abandon_machine(transport, e.what());
      throw;
    }
    header = std::move(db->header);
  } else {
    header = receive_setup(options, plan, rank, transport, nodes);
    cache_pages = cache_pages_for(options, header);
  }
  const PagePlacement placement(options.shape.distribution, static_cast<int>(topology.size()), header.page_count);
  Executed executed =
      execute(header, topology, placement, cache_pages, nodes, options, Share{&plan, &transport, rank});
  MachineReport& report = executed.result.report;
  if (rank != 0) {
    report_to_rank_zero(transport, plan, rank, executed);
    return std::nullopt;
  }
  for (int q = 1; q < plan.ranks(); ++q)
    merge_rank(transport.receive(Tag::report, q), plan, report, executed.routers, executed.recorder.get());
  if (executed.recorder)
    report.recording =
        split_recording(transport, plan, topology, report, *executed.recorder, options.observe.record_packets);
  std::vector<const RouterCounters*> routers;
  for (const auto& r : executed.routers) routers.push_back(&r);
  report.network = network_stats(topology, routers);
  // Each rank traced its own first packets: keep the first ones of the machine.
  const std::uint64_t traced = options.observe.trace_routes;
  if (report.network.routes.size() > traced) report.network.routes.resize(traced);
  return std::move(executed.result);
}

SvmStats MachineReport::svm() const {
  SvmStats total;
  for (const auto& n : per_node) total += n.svm;
  return total;
}

ServerCounters MachineReport::served() const {
  ServerCounters total;
  for (const auto& n : per_node) {
    total.pages_served += n.served.pages_served;
    total.bytes_served += n.served.bytes_served;
    total.served_in_place += n.served.served_in_place;
  }
  return total;
}

tracer::RayStats MachineReport::rays() const {
  tracer::RayStats total;
  for (const auto& n : per_node) total += n.work.rays;
  return total;
}

std::uint64_t MachineReport::items_computed() const {
  std::uint64_t total = 0;
  for (const auto& n : per_node) total += n.work.items;
  return total;
}

double MachineReport::item_imbalance() const {
  std::vector<double> v;
  for (const auto& n : per_node) v.push_back(static_cast<double>(n.work.items));
  return imbalance(v);
}

double MachineReport::ray_imbalance() const {
  std::vector<double> v;
  for (const auto& n : per_node) v.push_back(static_cast<double>(n.work.rays.rays()));
  return imbalance(v);
}

double MachineReport::idle_share() const {
  double seconds = 0, idle = 0;
  for (const auto& thread : host_threads) {
    seconds += thread.seconds;
    idle += thread.idle_seconds;
  }
  return seconds > 0 ? idle / seconds : 0.0;
}

std::string format_routes(const MachineReport& report) {
  const KindNamer name = [](std::uint8_t kind) { return std::string(message_kind_name(kind)); };
  std::string out;
  for (const auto& record : report.network.routes) out += format_route(record, name) + "\n";
  return out;
}

}  // namespace nodes
