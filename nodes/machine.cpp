// The VM_pRAY machine: distribution of the pages, wiring of every process on
// the network, and the report (see machine.hpp for the protocol).
#include "nodes/machine.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>

#include "nodes/mailbox.hpp"
#include "topology/spec.hpp"

namespace nodes {

namespace {

// The hint that ends an error of a machine the memory could not hold.
std::string needs_more_memory(std::size_t nodes) {
  return "a machine of " + std::to_string(nodes) + " nodes needs more memory than this process may map (see ulimit -v)";
}

// Everything one processor holds during a run; addresses stay stable while
// its processes refer to them.
struct NodeState {
  std::unique_ptr<NodeSvm> svm;
  ServerCounters served;
  std::vector<std::unique_ptr<Outbox>> worker_out;
  std::vector<std::unique_ptr<WorkerPort>> worker_in;
  std::vector<WorkerCounters> work;
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

void validate(const MachineOptions& options) {
  if (options.workers_per_node < 1) throw std::invalid_argument("--workers-per-node must be at least 1");
  if (options.grain < 1) throw std::invalid_argument("--grain must be at least 1");
  if (options.buffer_capacity < 1) throw std::invalid_argument("network buffer capacity must be at least 1");
  if (options.prefetch > max_prefetch(options))
    throw std::invalid_argument("--prefetch must be at most " + std::to_string(max_prefetch(options)) +
                                " (a worker's answers and a page reply must fit the network buffer of " +
                                std::to_string(options.buffer_capacity) + " packets)");
}

unsigned thread_count(const MachineOptions& options, std::size_t nodes) {
  const unsigned wanted = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<std::size_t>(wanted, nodes));
}

// Moves each page from the host's database into its owner's memory.
std::vector<std::unique_ptr<NodeState>> distribute(tracer::Database& db, const PagePlacement& placement,
                                                   std::uint32_t cache_pages) {
  std::vector<std::unique_ptr<NodeState>> nodes;
  for (int n = 0; n < placement.nodes(); ++n) {
    std::vector<std::vector<std::byte>> own(placement.own_count(n));
    for (std::uint32_t i = 0; i < own.size(); ++i) own[i] = std::move(db.pages[placement.page_of(n, i)]);
    auto state = std::make_unique<NodeState>();
    state->svm = std::make_unique<NodeSvm>(
        NodeMemory(placement, n, db.header.page_size, std::move(own), cache_pages));
    nodes.push_back(std::move(state));
  }
  db.pages.clear();
  db.pages.shrink_to_fit();  // the host keeps no copy
  return nodes;
}

// Results the farmer may pass on before the collector runs.
constexpr std::size_t results_buffer = 16;

// Pixels a pixel computer traces between two yields: some tens of
// microseconds of tracing for one context switch.
constexpr std::uint32_t timeslice_items = 16;

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

  Outbox outbox(NodeId n, std::uint16_t port) const {
    const std::uint64_t ports = Ports::count(options.workers_per_node);
    return Outbox(net.injector(n, port), n * ports + port, processes);
  }
};

void spawn_node(const Wiring& w, NodeId n, NodeState& node) {
  const unsigned thread = w.net.thread_of(n);
  const std::string name = "node " + std::to_string(n);
  const int k = w.options.workers_per_node;
  node.mailbox = std::make_unique<Mailbox>(name + " page requests", static_cast<std::size_t>(w.processes) + 1);
  w.runtime.spawn(name + " page mailbox", thread,
                  [mb = node.mailbox.get(), in = w.net.port(n, Ports::page_server)] { mb->forward(in); });
  std::function<void()> serve_hook = w.timing ? w.timing->serve_hook(static_cast<int>(n)) : nullptr;
  w.runtime.spawn(name + " page server", thread, [n, &node, out = w.outbox(n, Ports::page_server), serve_hook] {
    PageServer(n, node.svm->memory(), node.mailbox->reader(), out, node.served, serve_hook).run();
  });
  node.work.resize(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i) {
    const auto port = static_cast<std::uint16_t>(Ports::first_worker + i);
    node.worker_out.push_back(std::make_unique<Outbox>(w.outbox(n, port)));
    node.worker_in.push_back(std::make_unique<WorkerPort>(w.net.port(n, port)));
    Outbox& out = *node.worker_out.back();
    WorkerPort& in = *node.worker_in.back();
    auto& counters = node.work[static_cast<std::size_t>(i)];
    PageFetch fetch = make_page_fetch(w.placement, port, in, out);
    std::function<void()> charge;
    if (w.timing) {
      ComputeMeter& meter = w.timing->add_meter(static_cast<int>(n), counters.rays);
      fetch = MachineTiming::charging_fetch(meter, std::move(fetch));
      charge = [&meter] { meter.charge(); };
    }
    SvmSource& source = node.svm->add_worker(std::move(fetch));
    // On one thread nobody waits across threads, and first-in first-out
    // order lets a router take more packets per wake-up; under virtual time
    // the scheduler orders by clock.
    const bool prioritised = !w.timing && w.runtime.threads() > 1;
    const std::uint32_t timeslice = prioritised ? timeslice_items : 0;
    w.runtime.spawn(
        name + " pixel computer " + std::to_string(i), thread,
        [&w, port, &source, &in, &out, &counters, charge, timeslice] {
          PixelComputer(port, w.options.prefetch, source, w.header, w.options.trace, w.grid, in, out, counters, charge,
                        timeslice, w.tile_clock)
              .run();
        },
        prioritised ? csp::Priority::low : csp::Priority::high);
  }
}

void spawn_host(const Wiring& w, Host& host) {
  const unsigned thread = w.net.thread_of(0);
  const auto nodes = static_cast<std::size_t>(w.net.topology().size());
  const auto workers = nodes * static_cast<std::size_t>(w.options.workers_per_node);
  // Outstanding for the farmer: P + 1 per worker, one per page server.
  host.mailbox = std::make_unique<Mailbox>("farmer requests", workers * (w.options.prefetch + 1u) + nodes);
  w.runtime.spawn("farmer mailbox", thread, [mb = host.mailbox.get(), in = w.net.port(0, Ports::farmer)] {
    mb->forward(in);
  });
  host.results = std::make_unique<csp::Channel<Packet>>("results", results_buffer);
  w.runtime.spawn("farmer", thread, [&w, &host, nodes, out = w.outbox(0, Ports::farmer)] {
    Farmer(*host.plan, static_cast<int>(nodes), w.options.workers_per_node, host.mailbox->reader(), out,
           host.results->writer(), [&net = w.net] { net.shutdown(); }, host.farmer)
        .run();
  });
  w.runtime.spawn("collector", thread, [&w, &host] {
    Collector(*host.frame, host.results->reader(), w.options.progress, &host.owners).run();
  });
}

// items: every pixel or corner sample, in scanline order.
tracer::Image assemble_image(const tracer::DatabaseHeader& header, const ItemGrid& grid,
                             const std::vector<tracer::Color>& items) {
  const int width = header.camera.width, height = header.camera.height;
  tracer::Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const auto at = [&](int sx, int sy) { return items[static_cast<std::size_t>(sy) * grid.width + sx]; };
      image.at(x, y) = grid.corners
                           ? tracer::Tracer::average_corners(at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1))
                           : at(x, y);
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

}  // namespace

std::uint32_t default_cache_pages(const tracer::DatabaseHeader& header) {
  constexpr std::uint32_t share = 8, floor_pages = 64;
  return std::max({std::uint32_t{1}, header.page_count / share, std::min(header.page_count, floor_pages)});
}

std::uint32_t cache_pages_for(const MachineOptions& options, const tracer::DatabaseHeader& header) {
  if (options.cache_pages && options.cache_kb)
    throw std::invalid_argument("give --cache-pages or --cache-kb, not both");
  if (options.cache_pages) {
    if (*options.cache_pages == 0) throw std::invalid_argument("--cache-pages must be at least 1");
    return *options.cache_pages;
  }
  if (options.cache_kb) {
    const std::uint64_t pages = *options.cache_kb * 1024 / header.page_size;
    if (pages == 0)
      throw std::invalid_argument("--cache-kb " + std::to_string(*options.cache_kb) + " is less than one page (" +
                                  std::to_string(header.page_size) + " bytes)");
    return static_cast<std::uint32_t>(std::min<std::uint64_t>(pages, UINT32_MAX));
  }
  return default_cache_pages(header);
}

MachineResult run_machine(tracer::Database db, const MachineOptions& options) {
  validate(options);
  const auto topology = topology::parse_topology(options.topology, options.nodes);
  const std::uint32_t cache_pages = cache_pages_for(options, db.header);
  const tracer::DatabaseHeader& header = db.header;
  const PagePlacement placement(options.distribution, static_cast<int>(topology.size()), header.page_count);
  auto nodes = distribute(db, placement, cache_pages);

  const auto started = std::chrono::steady_clock::now();
  std::optional<MachineTiming> timing;
  if (options.timing) timing.emplace(*options.timing, static_cast<int>(topology.size()));
  csp::RuntimeOptions runtime_options;
  runtime_options.threads = thread_count(options, topology.size());
  if (timing) runtime_options = timing->runtime_options(runtime_options.stack_size);
  csp::Runtime runtime(std::move(runtime_options));
  NetworkOptions net_options;
  net_options.buffer_capacity = options.buffer_capacity;
  net_options.ports_per_node = Ports::count(options.workers_per_node);
  net_options.trace_routes = options.trace_routes;
  net_options.trace_kinds = options.trace_kinds;
  if (timing) net_options.link = timing->model().link_model();
  Network net(runtime, topology, net_options);

  const bool corners = options.trace.spd_procedure;
  const int rows = header.camera.height + (corners ? 1 : 0);
  ItemGrid grid{header.camera.width + (corners ? 1 : 0), corners, {}};
  const std::vector<std::uint32_t> positions = item_positions(grid.width, rows, options.pixel_order);
  grid.positions = positions;
  const auto items = static_cast<std::uint32_t>(grid.width) * static_cast<std::uint32_t>(rows);
  const Wiring wiring{runtime,
                      net,
                      placement,
                      header,
                      options,
                      grid,
                      topology.size() * net_options.ports_per_node,
                      timing ? &*timing : nullptr,
                      options.record_tiles ? run_clock(started, timing.has_value()) : RunClock{}};
  Host host;
  host.plan = std::make_unique<WorkPlan>(items, options.grain, options.schedule, static_cast<int>(topology.size()),
                                         options.workers_per_node);
  host.frame = std::make_unique<FrameAssembler>(items, grid.positions);
  host.owners.assign(items, 0);
  for (std::size_t n = 0; n < nodes.size(); ++n) spawn_node(wiring, static_cast<NodeId>(n), *nodes[n]);
  spawn_host(wiring, host);
  try {
    runtime.run();
  } catch (const csp::ThreadNotStarted& e) {
    throw csp::ThreadNotStarted(std::string(e.what()) + "; try fewer --threads (" + std::to_string(runtime.threads()) +
                                " here), or see ulimit -v and ulimit -u");
  } catch (const csp::ProcessNotStarted& e) {
    throw csp::ProcessNotStarted(std::string(e.what()) + "; " + needs_more_memory(topology.size()));
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("a process of the machine ran out of memory; " + needs_more_memory(topology.size()));
  } catch (const csp::ProcessesFailed& e) {
    if (!e.out_of_memory()) throw;
    throw csp::ProcessesFailed(std::string(e.what()) + "; " + needs_more_memory(topology.size()), true);
  }

  MachineResult result;
  MachineReport& report = result.report;
  report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  report.host_threads = runtime.thread_use();
  if (timing) {
    report.cost_model = timing->model().describe();
    report.predicted_seconds = timing->predicted_seconds();
    report.compute_seconds = timing->compute_seconds();
  }
  report.topology = topology.spec();
  report.nodes = static_cast<int>(topology.size());
  report.threads = runtime.threads();
  report.workers_per_node = options.workers_per_node;
  report.prefetch = options.prefetch;
  report.cache_pages = cache_pages;
  report.page_size = header.page_size;
  report.page_count = header.page_count;
  report.items = items;
  for (const auto& node : nodes) report.per_node.push_back(node_report(*node));
  report.schedule = options.schedule;
  report.pixel_order = options.pixel_order;
  report.grain = options.grain;
  report.farmer = host.farmer;
  report.farmer.steals = host.plan->steals();
  report.collected = host.frame->received();
  report.owners = std::move(host.owners);
  report.network = net.stats();
  result.image = assemble_image(header, grid, host.frame->colors());
  return result;
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
