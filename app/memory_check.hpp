// The up-front memory check of `vmpray`: once the scene is read and before
// anything is built or traced, the bytes that the render's image-sized
// buffers will take at their peak are estimated from the options and the
// image size, and an image whose estimate exceeds the memory there is is
// refused at once, rather than by std::bad_alloc or the OOM killer after
// minutes of work.
//
// The estimate counts what grows with the image (memory_check.cpp lists
// each buffer): the float frames, the 8-bit copy the image writers encode,
// the machine's pixel order, collected colours, pixel owners, the pixel
// computers' tiles, tile records and their CSV text, and the ownership
// picture. The scene, its database and the nodes' caches grow with the
// scene, not the image, and are left out, as is the process's own few
// megabytes.
// Invariant: the estimate follows the renderers' allocations as they are;
// a change to those buffers changes it too (memory_check_test.cpp holds it
// to peak resident sizes measured on real runs).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "app/options.hpp"

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

// UsageError "--width/--height: a WxH image needs about X GB, more than this
// machine's Y GB" when the estimate exceeds `limit`.
void check_image_memory(const Options& options, int width, int height, const MemoryLimit& limit);

}  // namespace app
