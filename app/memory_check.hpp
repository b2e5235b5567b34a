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

#include "app/options.hpp"

namespace app {

// What an estimate is held against.
struct MemoryLimit {
  std::uint64_t bytes = UINT64_MAX;
  bool process_limit = false;  // the address space this process may map (ulimit -v), not the machine's memory
};

// The peak bytes of the image-sized buffers of rendering a width x height
// image with these options.
std::uint64_t image_memory_bytes(const Options& options, int width, int height);

// This machine's physical memory, or the address space this process may
// map if that is less; no limit if neither can be read.
MemoryLimit memory_limit();

// UsageError "--width/--height: a WxH image needs about X GB, more than this
// machine's Y GB" when the estimate exceeds `limit`.
void check_image_memory(const Options& options, int width, int height, const MemoryLimit& limit);

}  // namespace app
