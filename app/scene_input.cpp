// Scene loading for the command line; see scene_input.hpp.
#include "app/scene_input.hpp"

#include <filesystem>
#include <stdexcept>

#include "tracer/generators.hpp"
#include "tracer/nff.hpp"
#include "tracer/tessellate.hpp"

namespace app {
namespace {

bool looks_like_path(const std::string& s) {
  return s.find('/') != std::string::npos || s.ends_with(".nff") || s.ends_with(".gz");
}

tracer::Scene read_scene(const std::string& spec) {
  std::error_code ec;
  if (spec == "-" || std::filesystem::is_regular_file(spec, ec)) return tracer::load_nff_file(spec);
  if (looks_like_path(spec)) throw std::runtime_error(spec + ": no such file");
  try {
    return tracer::generate_scene(spec);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string(e.what()) + " (and no file of that name)");
  }
}

}  // namespace

tracer::Scene load_scene(const Options& o) {
  tracer::Scene scene = read_scene(o.scene);
  if (o.width > 0) scene.camera.width = o.width;
  if (o.height > 0) scene.camera.height = o.height;
  if (o.tessellate > 0) tracer::tessellate(scene, o.tessellate);
  return scene;
}

}  // namespace app
