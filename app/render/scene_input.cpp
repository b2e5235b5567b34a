// Scene loading for the command line; see scene_input.hpp.
#include "app/render/scene_input.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "app/render/memory_check.hpp"
#include "app/render/progress.hpp"
#include "tracer/generators.hpp"
#include "tracer/nff.hpp"
#include "tracer/tessellate.hpp"

namespace app {
namespace {

bool looks_like_path(const std::string& s) {
  return s.find('/') != std::string::npos || s.ends_with(".nff") || s.ends_with(".gz");
}

// Anything that exists and is not a directory is read as a file, so FIFOs,
// /dev/stdin and process substitutions work as well as regular files. A
// name that is no file says why in the system's words (strerror): no such
// file, a loop of symbolic links, a path through a file, no permission.
tracer::Scene read_scene(const std::string& spec, const tracer::TessellationCheck& check) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(spec, ec);
  const bool directory = std::filesystem::is_directory(status);
  if (spec == "-" || (std::filesystem::exists(status) && !directory)) return tracer::load_nff_file(spec);
  const std::string not_a_file = directory ? "is a directory, not an NFF file"
                                 : ec     ? ec.message()
                                          : std::string(std::strerror(ENOENT));
  if (looks_like_path(spec)) throw std::runtime_error(spec + ": " + not_a_file);
  try {
    return tracer::generate_scene(spec, check);
  } catch (const std::invalid_argument& e) {
    // A name that is neither a file nor a built-in is a bad argument, as a bad option value is.
    const std::string file_note = directory ? "that name " + not_a_file : "no file of that name";
    throw UsageError(std::string(e.what()) + " (and " + file_note + "; vmpray --help lists the built-in scenes)");
  }
}

}  // namespace

std::vector<std::string> scene_warnings(const tracer::Scene& scene) {
  std::vector<std::string> warnings;
  if (scene.objects.empty())
    warnings.push_back(scene.name + " has no objects: the image is its background colour alone");
  else if (scene.lights.empty())
    warnings.push_back(scene.name + " has no lights ('l'): every surface it shows renders black");
  return warnings;
}

// A tessellation too large for the memory is refused before it is made,
// as an image or a machine is (memory_check.hpp).
tracer::Scene load_scene(const Options& o) {
  const MemoryLimit limit = memory_limit();
  const bool shown = !o.quiet && stderr_is_terminal();
  tracer::Scene scene = in_phase("reading " + (o.scene == "-" ? std::string("standard input") : o.scene), shown, [&] {
    return read_scene(o.scene, [&](const tracer::Scene& untessellated, int resolution) {
      check_tessellation_memory("scene '" + o.scene + "'", untessellated, resolution, limit);
    });
  });
  for (const std::string& warning : scene_warnings(scene)) std::cerr << "vmpray: warning: " << warning << "\n";
  if (o.width > 0) scene.camera.width = o.width;
  if (o.height > 0) scene.camera.height = o.height;
  if (o.tessellate > 0) {
    check_tessellation_memory("--tessellate " + std::to_string(o.tessellate), scene, o.tessellate, limit);
    in_phase("tessellating", shown, [&] { tracer::tessellate(scene, o.tessellate); });
  }
  return scene;
}

}  // namespace app
