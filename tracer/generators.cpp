// Spec parsing and the table of built-in scenes (see generators.hpp).
#include "tracer/generators.hpp"

#include <charconv>
#include <functional>
#include <stdexcept>

#include "tracer/tessellate.hpp"

namespace tracer {
namespace {

struct Entry {
  const char* name;
  std::function<Scene(int)> make;  // takes the size
  int default_size;                // < 0: a named scene that takes no size
  int tessellation;                // named scenes: fixed -t level (0: none)
  const char* description;
};

const std::vector<Entry>& table() {
  static const std::vector<Entry> entries = {
      {"teapot", generate_teapot, 8, 0,
       "SPD teapot, size n: 64n^2-8n smooth triangles on an n x n checkerboard (default 8: the paper's Teapot, 4096 polygons)"},
      {"tetra", generate_tetra, 6, 0, "SPD tetra, size n: recursive tetrahedra, 4^n triangles (default 6)"},
      {"mount", generate_mount, 6, 0, "SPD mount, size n: fractal mountain of 2*4^n triangles, 4 glass spheres (default 6, max 7)"},
      {"rings", generate_rings, 7, 0, "SPD rings, size n: pyramid of dodecahedral rings, 5n(n+1)(2n+1) spheres and cylinders (default 7)"},
      {"balls", generate_balls, 4, 0, "SPD balls (sphereflake), size n: sum of 9^k spheres for k=0..n (default 4)"},
      {"gears", generate_gears, 4, 0, "SPD gears, size n: n^3 gears of two concave 144-gons and 144 rectangles each (default 4)"},
      {"tree", generate_tree, 11, 0, "SPD tree, size n: 2^(n+1)-1 cones and spheres branching on a field (default 11)"},
      {"mountain", generate_mount, -6, 6, "the paper's Mountain: mount:6:t6, 9920 polygons"},
      {"rings4", generate_rings, -4, 1, "the paper's Rings4: rings:4:t1, 18001 polygons (18002 with the backdrop as 2 triangles)"},
      {"tetra9", generate_tetra, -9, 0, "the paper's Tetra9: tetra:9, 262144 triangles"},
      {"tetra10", generate_tetra, -10, 0, "the paper's Tetra10: tetra:10, 1048576 triangles"},
  };
  return entries;
}

[[noreturn]] void bad_spec(std::string_view spec, const std::string& why) {
  throw std::invalid_argument("scene '" + std::string(spec) + "': " + why);
}

int parse_int(std::string_view spec, std::string_view text, const char* what) {
  int value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    bad_spec(spec, std::string("expected ") + what + ", got '" + std::string(text) + "'");
  return value;
}

std::vector<std::string_view> split(std::string_view spec) {
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    std::size_t colon = spec.find(':', start);
    parts.push_back(spec.substr(start, colon - start));
    if (colon == std::string_view::npos) return parts;
    start = colon + 1;
  }
}

}  // namespace

Scene generate_scene(std::string_view spec, const TessellationCheck& before_tessellating) {
  std::vector<std::string_view> parts = split(spec);
  const Entry* entry = nullptr;
  for (const Entry& e : table())
    if (parts[0] == e.name) entry = &e;
  if (!entry) bad_spec(spec, "unknown built-in scene");
  if (parts.size() > 3) bad_spec(spec, "expected NAME[:SIZE][:tRES]");
  int size = std::abs(entry->default_size), tess = entry->tessellation;
  std::size_t next = 1;
  if (next < parts.size() && !parts[next].starts_with('t')) {
    if (entry->default_size < 0) bad_spec(spec, std::string("'") + entry->name + "' takes no size");
    size = parse_int(spec, parts[next++], "a size");
  }
  if (next < parts.size()) {
    if (!parts[next].starts_with('t')) bad_spec(spec, "expected tRES after the size, got '" + std::string(parts[next]) + "'");
    tess = parse_int(spec, parts[next++].substr(1), "a tessellation level after 't'");
    if (tess < 1 || tess > kMaxTessellation)
      bad_spec(spec, "expected a tessellation level of 1.." + std::to_string(kMaxTessellation) + ", got " +
                         std::to_string(tess));
  }
  if (next != parts.size()) bad_spec(spec, "expected NAME[:SIZE][:tRES]");
  try {
    Scene scene = entry->make(size);
    if (tess != 0 && before_tessellating) before_tessellating(scene, tess);
    if (tess != 0) tessellate(scene, tess);
    scene.name = std::string(spec);
    return scene;
  } catch (const std::invalid_argument& e) {
    bad_spec(spec, e.what());
  }
}

std::vector<BuiltinScene> builtin_scenes() {
  std::vector<BuiltinScene> out;
  for (const Entry& e : table()) out.push_back({e.name, e.description});
  return out;
}

}  // namespace tracer
