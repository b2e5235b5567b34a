// A built-in scene at a square size, packed into pages of page_size bytes:
// the database the machine suites render; and a page's worth of bytes that
// tell which page they are, for the suites that script a node's memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tracer/database.hpp"
#include "tracer/generators.hpp"

namespace test {

inline tracer::Database make_db(const std::string& spec, std::uint32_t page_size, int size) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = size;
  scene.camera.height = size;
  tracer::BuildOptions build;
  build.page_size = page_size;
  return tracer::build_database(scene, build);
}

// page_size bytes, each from the page's number and its offset.
inline std::vector<std::byte> page_bytes(std::uint32_t page, std::size_t page_size) {
  std::vector<std::byte> bytes(page_size);
  for (std::size_t i = 0; i < page_size; ++i) bytes[i] = static_cast<std::byte>((page * 31 + i) & 0xff);
  return bytes;
}

}  // namespace test
