// Sphere and cone tessellation after SPD's lib_output_polygon_sphere and
// lib_output_polygon_cylcone (see tessellate.hpp for the scheme).
#include "tracer/tessellate.hpp"

#include <algorithm>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tracer/gen_spd.hpp"

namespace tracer {
namespace {

void check_resolution(int resolution) {
  if (resolution < 1 || resolution > kMaxTessellation)
    throw std::invalid_argument("tessellation resolution " + std::to_string(resolution) + " out of range 1.." +
                                std::to_string(kMaxTessellation));
}

// SPD's step from one cube face to the next: a quarter turn in one plane,
// cycling through the planes so the six faces are each visited once.
void next_cube_face(Vec3d& v, int face) {
  switch ((face + 2) % 3) {
    case 0: v = {-v.y, v.x, v.z}; break;
    case 1: v = {v.x, -v.z, v.y}; break;
    default: v = {-v.z, v.y, v.x}; break;
  }
}

// Only the inside of these is visible, which the renderer's two-sided
// triangles cannot express (a ray from outside would stop at the near side).
bool inside_only(const Sphere& s) { return s.radius < 0; }
bool inside_only(const Cone& c) { return c.base_radius < 0 || c.apex_radius < 0; }

bool degenerate(const Patch& tri) {
  return length(cross(tri.vertices[1] - tri.vertices[0], tri.vertices[2] - tri.vertices[0])) == 0;
}

}  // namespace

std::vector<Patch> tessellate_sphere(const Sphere& sphere, int r) {
  check_resolution(r);
  const auto n = static_cast<std::size_t>(r) + 1;
  // Unit directions of the +Z face grid, at equal angles along each side.
  std::vector<Vec3d> grid(n * n);
  for (std::size_t u = 0; u < n; ++u)
    for (std::size_t v = 0; v < n; ++v) {
      double a = std::numbers::pi / 4 * (2.0 * double(u) / r - 1), b = std::numbers::pi / 4 * (2.0 * double(v) / r - 1);
      grid[u * n + v] = normalize(Vec3d{std::tan(a), -std::tan(b), 1});
    }
  std::vector<Patch> out;
  out.reserve(12 * n * n);
  for (int face = 0; face < 6; ++face) {
    for (Vec3d& d : grid) next_cube_face(d, face);
    for (std::size_t u = 0; u + 1 < n; ++u)
      for (std::size_t v = 0; v + 1 < n; ++v) {
        const std::size_t quad[4] = {u * n + v, u * n + v + 1, (u + 1) * n + v + 1, (u + 1) * n + v};
        for (int tri = 0; tri < 2; ++tri) {
          Patch p;
          for (int k = 0; k < 3; ++k) {
            const Vec3d& d = grid[quad[(tri * 2 + k) % 4]];
            p.vertices.push_back(sphere.center + d * sphere.radius);
            p.normals.push_back(d);
          }
          out.push_back(std::move(p));
        }
      }
  }
  return out;
}

std::vector<Patch> tessellate_cone(const Cone& cone, int r) {
  check_resolution(r);
  Vec3d axis = cone.apex - cone.base;
  double height = length(axis);
  Vec3d unit_axis = axis / height;
  Vec3d start = cross(axis, Vec3d{0, 0, 1});
  if (length(start) < 1e-12 * height) start = cross(axis, Vec3d{1, 0, 0});
  start = normalize(start);
  // Surface normal of the side along `start`: tilted by the radius change.
  Vec3d start_normal = normalize(start * height + unit_axis * (cone.base_radius - cone.apex_radius));
  Vec3d base_pt = cone.base + start * cone.base_radius, apex_pt = cone.apex + start * cone.apex_radius;
  Vec3d base_n = start_normal, apex_n = start_normal;
  std::vector<Patch> out;
  const int slices = 4 * r;
  for (int i = 1; i <= slices; ++i) {
    double angle = 2 * std::numbers::pi * i / slices;
    Vec3d n = spd::rotate(start_normal, unit_axis, angle);
    Vec3d next_apex = cone.apex + spd::rotate(start, unit_axis, angle) * cone.apex_radius;
    Vec3d next_base = cone.base + spd::rotate(start, unit_axis, angle) * cone.base_radius;
    Patch upper{{next_apex, apex_pt, base_pt}, {n, apex_n, base_n}};
    Patch lower{{next_base, next_apex, base_pt}, {n, n, base_n}};
    for (Patch* p : {&upper, &lower})
      if (!degenerate(*p)) out.push_back(std::move(*p));
    apex_pt = next_apex, apex_n = n, base_pt = next_base, base_n = n;
  }
  return out;
}

std::uint64_t tessellated_object_count(const Scene& scene, int resolution) {
  const auto r = static_cast<std::uint64_t>(std::max(resolution, 0));
  std::uint64_t count = 0;
  for (const Object& o : scene.objects) {
    const auto* s = std::get_if<Sphere>(&o.shape);
    const auto* c = std::get_if<Cone>(&o.shape);
    if (s && !inside_only(*s)) count += 12 * r * r;
    else if (c && !inside_only(*c)) count += 8 * r;
    else ++count;
  }
  return count;
}

void tessellate(Scene& scene, int resolution) {
  check_resolution(resolution);
  BigVector<Object> objects;
  // Room for every piece at once (fewer only where one is degenerate), so
  // that the objects are never moved while they grow: two copies at once.
  objects.reserve(tessellated_object_count(scene, resolution));
  for (Object& o : scene.objects) {
    std::vector<Patch> pieces;
    auto* s = std::get_if<Sphere>(&o.shape);
    auto* c = std::get_if<Cone>(&o.shape);
    if (s && !inside_only(*s)) pieces = tessellate_sphere(*s, resolution);
    else if (c && !inside_only(*c)) pieces = tessellate_cone(*c, resolution);
    else {
      objects.push_back(std::move(o));
      continue;
    }
    for (Patch& p : pieces) objects.push_back({std::move(p), o.material});
  }
  scene.objects = std::move(objects);
}

}  // namespace tracer
