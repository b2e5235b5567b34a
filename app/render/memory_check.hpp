// The up-front memory check of `vmpray`: before anything is built or
// traced, the peak bytes of the render's image-sized buffers are estimated
// from the options and the image size, and once the database is built the
// machine's (nodes, links, relays between threads, a replay's recording);
// a run whose estimate exceeds the memory there is (the machine's, the
// control group's, or under ulimit -v the address space, stacks counted
// whole) is refused at once, rather than by std::bad_alloc or the OOM
// killer after minutes of work. memory_check.cpp lists each buffer counted.
// Left out: the scene, its database (but for the copy each of a sweep's
// side-by-side runs holds), the nodes' caches and the process's own few
// megabytes. Invariant: the estimates follow the allocations as they are;
// scripts/memory-matrix.py holds them to peaks measured on real runs (CI
// runs its quick rows), and memory_check_test.cpp to what they count.
#pragma once

#include <cstdint>
#include <filesystem>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/render/options.hpp"
#include "tracer/scene.hpp"

namespace app {

// What an estimate is held against.
struct MemoryLimit {
  enum class Source {
    machine,        // the machine's physical memory
    control_group,  // what this process's control group may use (a container's limit)
    address_space,  // the address space this process may map (ulimit -v)
  };
  std::uint64_t bytes = UINT64_MAX;
  Source source = Source::machine;
};

// The peak bytes of the image-sized buffers of rendering a width x height
// image with these options.
std::uint64_t image_memory_bytes(const Options& options, int width, int height);

// The memory limit of this process's control group: the least memory.max
// (cgroup v2) or memory.limit_in_bytes (v1) on its path from its own group
// up to the root of the hierarchy. `root` is where the cgroup file system is
// mounted (/sys/fs/cgroup, holding the v1 hierarchies by controller, or v2's
// if it is unified), `membership` the text of /proc/self/cgroup. nullopt when
// no group on the path sets a limit, or none can be read.
std::optional<std::uint64_t> cgroup_memory_limit(const std::filesystem::path& root, const std::string& membership);

// The least of this machine's physical memory, its control group's limit and
// the address space this process may map; no limit if none can be read.
MemoryLimit memory_limit();

// "out of memory WHAT: it needs more than the 879 MB this process may map
// (ulimit -v)", the limit being memory_limit() as the checks here name it.
std::string out_of_memory_line(const std::string& what);

// work(), with a std::bad_alloc out of it turned into a std::runtime_error
// of out_of_memory_line(what): the steps whose memory no check foresees
// (reading a scene, building its database) end on a line saying where and
// against which limit memory ran out.
template <class Work>
auto naming_memory_shortage(const std::string& what, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(out_of_memory_line(what));
  }
}

// UsageError "--width/--height: a WxH image needs about X GB, more than this
// machine's Y GB" when the estimate exceeds `limit`.
void check_image_memory(const Options& options, int width, int height, const MemoryLimit& limit);
// The same for the scene's image, naming the scene's "FILE:LINE" instead of
// the options when the size is the one its "resolution" set.
void check_image_memory(const Options& options, const tracer::Scene& scene, const MemoryLimit& limit);

// The peak bytes of a scene tessellated at `resolution` and its database:
// every object it would then have (tracer::tessellated_object_count) as a
// scene object and as a database primitive with its share of the
// acceleration structure and of the pages.
std::uint64_t tessellation_memory_bytes(const tracer::Scene& scene, int resolution);

// UsageError "ORIGIN: the scene tessellated becomes N objects, needing about
// X GB, more than this machine's Y GB" when the estimate exceeds `limit`;
// `origin` names what asked for it ("--tessellate 64", "scene 'rings:1:t60'").
void check_tessellation_memory(const std::string& origin, const tracer::Scene& scene, int resolution,
                               const MemoryLimit& limit);

// The bytes a machine takes beyond its image's buffers, with a database of
// `page_count` pages: every node's processes and their fixed state, its
// page table and its pixel computers' page stamps (4 bytes a page each);
// every link queue with the router's state for it, and in virtual time the
// link process that carries it; the relays of the links between threads;
// and a replay's recording at its bound (--replay-packets). Per-node and
// per-queue sizes are measured (scripts/memory-matrix.py). Left out: the
// database's own pages, which the host hands over as it distributes them,
// and the caches, which fill only as far as the render touches pages. Under
// an address-space limit (ulimit -v) the checks hold it the bytes mapped:
// every process's whole stack besides.
struct MachineMemory {
  std::string spec;  // the topology, "complete:4096"
  std::uint64_t nodes = 0, link_queues = 0;
  unsigned threads = 1;                     // the run's threads
  std::uint64_t relayed_link_queues = 0;    // link queues between threads
  std::uint64_t node_bytes = 0, link_bytes = 0, relay_bytes = 0, recording_bytes = 0;
  std::uint64_t reserved_bytes = 0;  // the processes' whole stacks, mapped beyond what is resident
  std::uint64_t total() const { return node_bytes + link_bytes + relay_bytes + recording_bytes; }
  // What ulimit -v holds: the stacks whole, and a seventh more for what the
  // allocator maps beyond what it touches (its arenas' reserves, vectors
  // moved as they grow): peaks of mapped bytes (VmPeak) measured up to 13%
  // above the rest.
  std::uint64_t mapped() const { return (total() + reserved_bytes) * 115 / 100; }
};
MachineMemory machine_memory(const Options& options, std::uint32_t page_count);
std::uint64_t machine_memory_bytes(const Options& options, std::uint32_t page_count);

// UsageError "--nodes/--topology: complete:4096 (4096 nodes, 16773120 link
// queues, ...) needs about X GB with its image, more than this machine's
// Y GB" when the machine's estimate and the image's together exceed `limit`.
void check_machine_memory(const Options& options, int width, int height, std::uint32_t page_count,
                          const MemoryLimit& limit);

// What --estimate-memory prints: the estimate, its parts and the limit.
std::string describe_memory(const Options& options, int width, int height, std::uint32_t page_count,
                            const MemoryLimit& limit);

// For runs that may go side by side (a sweep's) on up to `jobs` threads,
// each on its own copy of a database of `page_count` pages of `page_size`
// bytes (the host hands its pages to the nodes, so a run keeps that copy):
// the UsageError of check_machine_memory for the first run that does not
// fit alone; else how many of them, at most `jobs` and at least 1, fit at
// once whichever run together (the largest ones do).
unsigned jobs_that_fit(const std::vector<nodes::MachineOptions>& machines, int width, int height,
                       std::uint32_t page_count, std::size_t page_size, unsigned jobs, const MemoryLimit& limit);

}  // namespace app
