// A built-in scene at a square size, packed into pages of page_size bytes:
// the database the machine suites render.
#pragma once

#include <string>

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

}  // namespace test
