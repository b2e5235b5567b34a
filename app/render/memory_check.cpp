// The up-front memory estimate and check (see memory_check.hpp).
//
// Items are what the machine farms out: the pixels, or with the SPD
// procedure the (W+1) x (H+1) corner samples. Bytes per pixel or item:
//   --single        the frame render_frame returns, which becomes the
//                   result's image (12), and as it is written the 8-bit
//                   copy (3)
//   machine run     the collector's colours (12 an item), arrival bits
//                   (1/8) and owners (2); the Hilbert order (4); and the
//                   pixel computers' tiles, each keeping the colours of
//                   its largest and sending them in a result of the same
//                   size (12 + 12 an item of tile)
//   its assembly    the same, with the assembled image (12) in place of
//                   the tiles, whose processes have ended; it becomes the
//                   result's image
//   the outputs     the image and owners, and the 8-bit copy (3) each
//                   image writer encodes; the ownership picture (12) for
//                   --ownership or --report (the page takes it and the
//                   image themselves, not copies); the page's text, which
//                   embeds both as PNG, is not counted: compressed, it is
//                   a small part of the rest (0.15 bytes a pixel, teapot at 4096x4096)
//   tile records    with tiles recorded in the dynamic schedule: in the
//                   run, each tile's record (48 bytes) in its pixel
//                   computer's vector and in its node report's copy (the
//                   vector grows by doubling, but what it has not filled
//                   is not resident); in the outputs, the report's copy,
//                   and for --tiles the CSV's sorted rows (16 bytes a
//                   tile) and its text (about 40), held two and a half
//                   times over as its buffer grows and is copied out; the
//                   affinity and static schedules make too few tiles to
//                   count
// A virtual-time run, or --compare-serial, runs the 1-node machine first.
// Measured peak resident sizes, less the 64x64 run's, match these within 5%
// on teapot from 1024x1024 to 16384x16384, and within 10% where tile records
// weigh: what their buffers' reallocations leave resident varies from run to
// run (memory_check_test.cpp).
#include "app/render/memory_check.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "app/render/cpu_count.hpp"
#include "csp/runtime.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "nodes/machine/work_plan.hpp"
#include "nodes/net/network.hpp"
#include "nodes/net/thread_relay.hpp"
#include "topology/topology.hpp"
#include "tracer/tessellate.hpp"
#include "tracer/vec.hpp"

namespace app {
namespace {

constexpr std::uint64_t colour = sizeof(tracer::Color);        // a float pixel or sample
constexpr std::uint64_t rgb8 = 3;                              // a pixel of the encoded 8-bit image
constexpr std::uint64_t owner = sizeof(std::uint16_t);         // the node that computed an item
constexpr std::uint64_t position = sizeof(std::uint32_t);      // an item's place in the Hilbert order
constexpr std::uint64_t tile_record = sizeof(nodes::TileSpan);
constexpr std::uint64_t csv_row = sizeof(std::size_t) + sizeof(void*);  // a tile's place in the CSV's order
constexpr std::uint64_t csv_line = 40;                                   // a tile's line of CSV text, about

// The items of the largest tile a pixel computer gets, one of `workers`.
std::uint64_t largest_tile(const nodes::MachineOptions& m, std::uint64_t items, std::uint64_t workers) {
  const std::uint64_t share = (items + workers - 1) / workers;
  switch (m.farming.schedule) {
    case nodes::Schedule::static_split: return share;
    case nodes::Schedule::dynamic: return std::min<std::uint64_t>(m.farming.grain, items);
    case nodes::Schedule::affinity: break;
  }
  // The first tile off a worker's own share; what it takes from others later is smaller.
  const std::uint64_t parts = std::max<std::uint64_t>(workers, nodes::WorkPlan::min_affinity_parts);
  return std::min(share, std::max<std::uint64_t>(m.farming.grain, (share + parts - 1) / parts));
}

// The tiles of a dynamic run whose tiles are recorded; 0 otherwise.
std::uint64_t recorded_tiles(const nodes::MachineOptions& m, std::uint64_t items) {
  if ((!m.observe.record_tiles && !m.observe.record) || m.farming.schedule != nodes::Schedule::dynamic) return 0;
  return (items + m.farming.grain - 1) / m.farming.grain;
}

// One run of the machine on `workers` pixel computers: the larger of its
// peak while the pixel computers work and its peak as it assembles the image.
std::uint64_t machine_run_bytes(const Options& o, std::uint64_t pixels, std::uint64_t items,
                                std::uint64_t workers) {
  const nodes::MachineOptions& m = o.machine;
  std::uint64_t held = (colour + owner) * items + items / 8;
  if (m.farming.pixel_order == nodes::PixelOrder::hilbert) held += position * items;
  const std::uint64_t largest = largest_tile(m, items, workers);
  const std::uint64_t tiles = std::min(items, workers * largest) + largest;  // kept, and one result on its way
  const std::uint64_t records = recorded_tiles(m, items) * tile_record * 2;
  return held + std::max(colour * tiles, colour * pixels) + records;
}

// Writing the outputs of a machine render.
std::uint64_t machine_output_bytes(const Options& o, std::uint64_t pixels, std::uint64_t items) {
  const std::uint64_t tiles = recorded_tiles(o.machine, items);
  std::uint64_t bytes = (colour + rgb8) * pixels + owner * items + tiles * tile_record;
  if (!o.tiles_csv.empty()) bytes += tiles * (csv_row + csv_line * 5 / 2);
  if (!o.pictures.ownership_png.empty() || !o.pictures.report_html.empty()) bytes += colour * pixels;
  return bytes;
}

// "6.4 GB", or "350 MB" below a gigabyte.
std::string about(std::uint64_t bytes) {
  char text[32];
  if (bytes >= 1'000'000'000) std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) / 1e9);
  else std::snprintf(text, sizeof text, "%.0f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

}  // namespace

std::uint64_t image_memory_bytes(const Options& o, int width, int height) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  if (o.single) return (colour + rgb8) * pixels;  // its outputs: more than the render takes
  const std::uint64_t items =
      o.spd_procedure ? static_cast<std::uint64_t>(width + 1) * static_cast<std::uint64_t>(height + 1) : pixels;
  const std::uint64_t per_node = static_cast<std::uint64_t>(o.machine.shape.workers_per_node);
  const std::uint64_t nodes = o.machine.topology.size();
  std::uint64_t bytes = std::max(machine_run_bytes(o, pixels, items, nodes * per_node),
                                 machine_output_bytes(o, pixels, items));
  if (o.compare_serial || o.machine.timing) bytes = std::max(bytes, machine_run_bytes(o, pixels, items, per_node));
  return bytes;
}

namespace {

// The number in a control group's limit file, or nullopt for "max", a
// missing file or anything else.
std::optional<std::uint64_t> read_limit_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::uint64_t bytes = 0;
  if (in >> bytes) return bytes;
  return std::nullopt;
}

}  // namespace

std::optional<std::uint64_t> cgroup_memory_limit(const std::filesystem::path& root, const std::string& membership) {
  std::optional<std::uint64_t> least;
  std::istringstream lines(membership);
  for (std::string line; std::getline(lines, line);) {
    // hierarchy-ID:controller-list:path; v2's one hierarchy has ID 0 and no controllers listed.
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string_view controllers = std::string_view(line).substr(first + 1, second - first - 1);
    bool memory = false;
    for (std::size_t at = 0; at <= controllers.size();) {
      const std::size_t comma = std::min(controllers.find(',', at), controllers.size());
      memory = memory || controllers.substr(at, comma - at) == "memory";
      at = comma + 1;
    }
    const bool v2 = line.compare(0, first, "0") == 0 && controllers.empty();
    if (!v2 && !memory) continue;
    const std::filesystem::path hierarchy = v2 ? root : root / "memory";
    const char* file = v2 ? "memory.max" : "memory.limit_in_bytes";
    for (std::filesystem::path group = std::filesystem::path(line.substr(second + 1)).relative_path();;
         group = group.parent_path()) {
      if (const auto bytes = read_limit_file(hierarchy / group / file))
        least = std::min(least.value_or(UINT64_MAX), *bytes);
      if (group.empty()) break;
    }
  }
  return least;
}

// The machine's physical memory rather than MemAvailable: what is available
// moves from moment to moment with other processes and the page cache, so a
// check against it would refuse a run that could have fitted once they made
// room, and one command line would pass or fail by the moment it was typed.
// An image larger than the whole memory cannot be rendered (short of a swap
// that turns minutes into hours); the check refuses what surely does not
// fit, and promises nothing of what passes it.
MemoryLimit memory_limit() {
  MemoryLimit limit;
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page_size > 0) limit.bytes = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size);
  // A container's limit: past it the kernel reclaims, then kills.
  std::ifstream membership_file("/proc/self/cgroup");
  std::ostringstream membership;
  membership << membership_file.rdbuf();
  if (const auto group = cgroup_memory_limit("/sys/fs/cgroup", membership.str()); group && *group < limit.bytes)
    limit = {*group, MemoryLimit::Source::control_group};
  // Resident bytes are mapped bytes too: an address-space limit below the
  // memory fails the allocations first.
  rlimit space{};
  if (getrlimit(RLIMIT_AS, &space) == 0 && space.rlim_cur != RLIM_INFINITY && space.rlim_cur < limit.bytes)
    limit = {static_cast<std::uint64_t>(space.rlim_cur), MemoryLimit::Source::address_space};
  return limit;
}

namespace {

// "this machine's 4.3 GB", "the 200 MB this process may map (ulimit -v)".
std::string available(const MemoryLimit& limit) {
  switch (limit.source) {
    case MemoryLimit::Source::control_group:
      return "the " + about(limit.bytes) + " this process's control group may use";
    case MemoryLimit::Source::address_space:
      return "the " + about(limit.bytes) + " this process may map (ulimit -v)";
    case MemoryLimit::Source::machine:
      break;
  }
  return "this machine's " + about(limit.bytes);
}

}  // namespace

std::string out_of_memory_line(const std::string& what) {
  return "out of memory " + what + ": it needs more than " + available(memory_limit());
}

namespace {

// Resident bytes of a machine, measured on teapot at 16x16 (so that the
// image weighs nothing) on one thread, above the 1-node machine's, fitted
// over complete graphs, hypercubes, rings, tori and meshes
// (scripts/memory-matrix.py measures them again): a node's router, page
// server, page mailbox, their stacks and state; a pixel computer's stack,
// tracer and channels; a link queue (a channel, whose slots come with its
// first packet) with the router's guard, pending slot and counters for it,
// and in virtual time its link process (stack and channel). A link between
// threads adds its relays' state and a queue at the sender, and its
// share of the rings: K packet entries and two credit entries
// (ThreadRelays). A replay's recording takes about 600 bytes a packet
// recorded and 240 a hop it makes (the topology's average distance): its
// hops, the waits and serves around it and the page's text.
constexpr std::uint64_t node_bytes = 38 * 1024, virtual_node_bytes = 67 * 1024;
constexpr std::uint64_t worker_bytes = 7680;
constexpr std::uint64_t link_queue_bytes = 640, virtual_link_queue_bytes = 9600;
constexpr std::uint64_t relayed_link_bytes = 576;
constexpr std::uint64_t ring_entry_bytes = nodes::ThreadRelays::ring_entry_bytes;
constexpr std::uint64_t recorded_packet_bytes = 600, recorded_hop_bytes = 240;  // a packet, and each hop it makes
constexpr std::uint64_t page_entry = sizeof(std::int32_t);  // a node's page table, and a tracer's page stamps
constexpr std::uint64_t host_processes = 4;  // the farmer, the collector, and room for a bridge
constexpr std::uint64_t guard_page = 4096;

std::uint64_t link_queues(const topology::Topology& t) {
  std::uint64_t ports = 0;
  for (topology::NodeId n = 0; n < t.size(); ++n) ports += t.degree(n);
  return ports * t.buffer_classes();
}

// The threads a run of `nodes` nodes gets (nodes::thread_count), with the
// CPUs this process may use.
unsigned run_threads(nodes::MachineOptions m, std::size_t nodes) {
  if (m.threads.count == 0 && m.threads.cpus == 0) m.threads.cpus = usable_cpus();
  return nodes::thread_count(m, nodes);
}

// Link queues whose ends run on different threads, nodes placed in blocks
// (nodes::Network::block_placement); none when links between threads are
// plain channels or in virtual time (one thread).
std::uint64_t relayed_link_queues(const nodes::MachineOptions& m, const topology::Topology& t, unsigned threads) {
  if (threads < 2 || !m.threads.relay_between || m.timing) return 0;
  std::uint64_t relayed = 0;
  for (topology::NodeId n = 0; n < t.size(); ++n) {
    const unsigned from = nodes::Network::block_placement(n, t.size(), threads);
    for (const topology::NodeId next : t.neighbours(n))
      relayed += nodes::Network::block_placement(next, t.size(), threads) != from;
  }
  return relayed * t.buffer_classes();
}

}  // namespace

MachineMemory machine_memory(const Options& o, std::uint32_t page_count) {
  const nodes::MachineOptions& m = o.machine;
  const topology::Topology& t = m.topology;
  const bool virtual_time = m.timing.has_value();
  const auto workers = static_cast<std::uint64_t>(m.shape.workers_per_node);
  MachineMemory r;
  r.spec = t.spec();
  r.nodes = t.size();
  r.threads = virtual_time ? 1 : run_threads(m, t.size());
  r.link_queues = link_queues(t);
  r.relayed_link_queues = relayed_link_queues(m, t, r.threads);
  r.node_bytes = t.size() * ((virtual_time ? virtual_node_bytes : node_bytes) + workers * worker_bytes +
                             (1 + workers) * page_entry * page_count);
  r.link_bytes = r.link_queues * (virtual_time ? virtual_link_queue_bytes : link_queue_bytes);
  const std::uint64_t ring_entries =
      m.shape.buffer_capacity + nodes::ThreadRelays::credit_entries(m.shape.buffer_capacity);
  r.relay_bytes = r.relayed_link_queues * (relayed_link_bytes + ring_entries * ring_entry_bytes);
  const double per_packet = recorded_packet_bytes + t.average_distance() * recorded_hop_bytes;
  r.recording_bytes =
      m.observe.record ? static_cast<std::uint64_t>(static_cast<double>(m.observe.record_packets) * per_packet) : 0;
  // Every process's stack is mapped whole as it starts, with its guard
  // page, resident or not: per node its router, page server and pixel
  // computers, in virtual time its page mailbox and a link process per
  // queue; a relay a thread; the host's.
  const std::uint64_t processes = t.size() * (2 + workers + (virtual_time ? 1 : 0)) +
                                  (virtual_time ? r.link_queues : 0) + r.threads + host_processes;
  r.reserved_bytes = processes * (csp::RuntimeOptions{}.stack_size + guard_page);
  return r;
}

std::uint64_t machine_memory_bytes(const Options& o, std::uint32_t page_count) {
  return machine_memory(o, page_count).total();
}

namespace {

// `origin` is what set the size: the options, or the scene's file:line.
void check_image_memory(const Options& o, int width, int height, const MemoryLimit& limit,
                        const std::string& origin, const std::string& hint) {
  const std::uint64_t needed = image_memory_bytes(o, width, height);
  if (needed <= limit.bytes) return;
  throw UsageError(origin + ": a " + std::to_string(width) + "x" + std::to_string(height) + " image needs about " +
                   about(needed) + ", more than " + available(limit) + hint);
}

}  // namespace

void check_image_memory(const Options& o, int width, int height, const MemoryLimit& limit) {
  check_image_memory(o, width, height, limit, "--width/--height", "");
}

void check_image_memory(const Options& o, const tracer::Scene& scene, const MemoryLimit& limit) {
  if (o.width > 0 || o.height > 0 || scene.resolution_origin.empty())
    return check_image_memory(o, scene.camera.width, scene.camera.height, limit);
  check_image_memory(o, scene.camera.width, scene.camera.height, limit, scene.resolution_origin,
                     "; --width and --height render it smaller");
}

// Peak resident bytes per object of a tessellated scene, measured on
// balls:3 (820 spheres) at --tessellate 8, 16 and 24 at 512x512 (343, 321
// and 319 bytes on the default machine, 267, 252 and 250 with --single),
// with a sixth to spare: a patch of three vertices and normals in the
// scene, its triangle in the build and its BVH share, its bytes in the
// pages, which the build frees as it goes.
constexpr std::uint64_t tessellated_object_bytes = 400;

std::uint64_t tessellation_memory_bytes(const tracer::Scene& scene, int resolution) {
  return tracer::tessellated_object_count(scene, resolution) * tessellated_object_bytes;
}

void check_tessellation_memory(const std::string& origin, const tracer::Scene& scene, int resolution,
                               const MemoryLimit& limit) {
  const std::uint64_t needed = tessellation_memory_bytes(scene, resolution);
  if (needed <= limit.bytes) return;
  throw UsageError(origin + ": the scene tessellated becomes " +
                   std::to_string(tracer::tessellated_object_count(scene, resolution)) + " objects, needing about " +
                   about(needed) + ", more than " + available(limit));
}

namespace {

// Resident bytes, or under an address-space limit the bytes mapped.
std::uint64_t machine_run_bytes(const Options& o, int width, int height, std::uint32_t page_count,
                                const MemoryLimit& limit) {
  const MachineMemory m = machine_memory(o, page_count);
  const bool mapped = limit.source == MemoryLimit::Source::address_space;
  return (mapped ? m.mapped() : m.total()) + image_memory_bytes(o, width, height);
}

// "complete:4096 (4096 nodes, 16773120 link queues, 8386560 of them between
// 2 threads)".
std::string machine_words(const MachineMemory& m) {
  std::string words = m.spec + " (" + std::to_string(m.nodes) + " nodes, " + std::to_string(m.link_queues) + " link queues";
  if (m.relayed_link_queues > 0)
    words += ", " + std::to_string(m.relayed_link_queues) + " of them between " + std::to_string(m.threads) + " threads";
  return words + ")";
}

void refuse_machine(const Options& o, std::uint64_t needed, std::uint32_t page_count, const MemoryLimit& limit) {
  const char* what = limit.source == MemoryLimit::Source::address_space ? " of address space" : "";
  throw UsageError("--nodes/--topology: " + machine_words(machine_memory(o, page_count)) + " needs about " +
                   about(needed) + what + " with its image, more than " + available(limit));
}

}  // namespace

void check_machine_memory(const Options& o, int width, int height, std::uint32_t page_count,
                          const MemoryLimit& limit) {
  const std::uint64_t needed = machine_run_bytes(o, width, height, page_count, limit);
  if (needed > limit.bytes) refuse_machine(o, needed, page_count, limit);
}

std::string describe_memory(const Options& o, int width, int height, std::uint32_t page_count,
                            const MemoryLimit& limit) {
  const MachineMemory m = machine_memory(o, page_count);
  const std::uint64_t image = image_memory_bytes(o, width, height);
  const std::uint64_t needed = (o.single ? 0 : m.total()) + image;
  const std::uint64_t mapped = (o.single ? 0 : m.mapped()) + image;
  // The comparison follows the figure the limit holds: the bytes mapped
  // under ulimit -v, else the resident ones.
  const bool address_space = limit.source == MemoryLimit::Source::address_space;
  const auto against = [&](std::uint64_t bytes) {
    return std::string(bytes > limit.bytes ? ", more" : ", less") + " than " + available(limit);
  };
  std::ostringstream text;
  text << "needs about " << about(needed) << " (" << needed << " bytes) resident"
       << (address_space ? "" : against(needed)) << ", and maps about " << about(mapped)
       << (address_space ? against(mapped) : "") << "\n";
  text << "  image " << width << "x" << height << ": " << about(image) << "\n";
  if (o.single) return text.str();
  text << "  machine " << machine_words(m) << ":\n";
  text << "    nodes " << about(m.node_bytes) << ", link queues " << about(m.link_bytes);
  if (m.relayed_link_queues > 0) text << ", relays between threads " << about(m.relay_bytes);
  if (m.recording_bytes > 0) text << ", the replay's recording " << about(m.recording_bytes);
  text << "\n    processes' stacks, mapped whole and resident as far as used: "
       << about(m.reserved_bytes) << "\n";
  return text.str();
}

unsigned jobs_that_fit(const std::vector<nodes::MachineOptions>& machines, int width, int height,
                       std::uint32_t page_count, std::size_t page_size, unsigned jobs, const MemoryLimit& limit) {
  const std::uint64_t database_copy = std::uint64_t{page_count} * page_size;
  std::vector<std::uint64_t> needs;
  for (const nodes::MachineOptions& machine : machines) {
    Options o;
    o.machine = machine;
    needs.push_back(database_copy + machine_run_bytes(o, width, height, page_count, limit));
    if (needs.back() > limit.bytes) refuse_machine(o, needs.back(), page_count, limit);
  }
  std::sort(needs.begin(), needs.end(), std::greater<>());
  unsigned fit = 1;
  std::uint64_t together = needs.empty() ? 0 : needs.front();
  for (; fit < jobs && fit < needs.size() && together + needs[fit] <= limit.bytes; ++fit) together += needs[fit];
  return fit;
}

}  // namespace app
