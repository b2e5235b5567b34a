// The host-side scene: what an NFF file (or a built-in generator) says, in
// double precision, before any acceleration structure or paging exists.
// Invariants once a Scene is returned by the parser or a generator:
//  - every object's material index is < materials.size();
//  - polygons and patches have >= 3 vertices, patches one normal per vertex;
//  - every number is finite; sphere/cone radii are non-zero (negative means
//    "inside visible only", as NFF allows);
//  - camera.width, camera.height >= 1.
#pragma once

// GCC 12 warns that Boost's copy of a small vector may read past the inline
// elements, on a size it cannot bound (-Wstringop-overread, a false positive
// of its middle end, which also reaches code in system headers).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-overread"
#endif
#include <boost/container/small_vector.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "tracer/huge_pages.hpp"
#include "tracer/vec.hpp"

namespace tracer {

// NFF "v": angle is the full field of view between the centres of the first
// and last pixel rows/columns; up need not be perpendicular to at - from.
struct Camera {
  Vec3d from{0, 0, 1};
  Vec3d at{0, 0, 0};
  Vec3d up{0, 1, 0};
  double angle_deg = 45.0;
  double hither = 1e-3;
  int width = 512;
  int height = 512;
};

// NFF "l": a positional light; SPD files give no colour (white is implied).
struct Light {
  Vec3d position;
  Color color{1, 1, 1};
};

// NFF "f": colour, diffuse Kd, specular Ks, Phong exponent, transmittance T,
// index of refraction.  Objects with T > 0 are two-sided.
struct Material {
  Color color{1, 1, 1};
  double kd = 1.0;
  double ks = 0.0;
  double shine = 0.0;
  double transmittance = 0.0;
  double ior = 1.0;
};

// NFF "s": negative radius means only the inside is visible.
struct Sphere {
  Vec3d center;
  double radius = 1.0;
};

// NFF "c": cone or cylinder between base and apex, no end caps.
struct Cone {
  Vec3d base;
  double base_radius = 1.0;
  Vec3d apex;
  double apex_radius = 1.0;
};

// A polygon's or patch's vertices: three held in the object itself, more
// on the heap. A big scene is mostly triangles, which then cost no
// allocation of their own: Tetra10's million make 136 MB, not 160 MB with a
// vector apiece (and a tessellated patch 216 bytes, not 240).
using Vertices = boost::container::small_vector<Vec3d, 3>;
inline std::span<const Vec3d> points(const Vertices& v) { return {v.data(), v.size()}; }

// NFF "p": planar, one-sided, counter-clockwise seen from the visible side;
// the first three vertices form a convex corner and fix the normal.
struct Polygon {
  Vertices vertices;
};

// NFF "pp": a polygon with a normal per vertex, smooth-shaded.
struct Patch {
  Vertices vertices;
  std::vector<Vec3d> normals;
};

using Shape = std::variant<Sphere, Cone, Polygon, Patch>;

struct Object {
  Shape shape;
  std::uint32_t material = 0;
};

struct Scene {
  std::string name;  // file name or generator spec, for reports
  Camera camera;
  std::string resolution_origin;  // "FILE:LINE" of the NFF "resolution" that set the size; empty for built-ins
  Color background{0, 0, 0};
  std::vector<Light> lights;
  std::vector<Material> materials;
  BigVector<Object> objects;  // large scenes' storage advised for huge pages

  // Polygons as the paper counts them: "p" and "pp" entities.
  std::size_t polygon_count() const {
    std::size_t n = 0;
    for (const auto& o : objects)
      n += std::holds_alternative<Polygon>(o.shape) || std::holds_alternative<Patch>(o.shape);
    return n;
  }
};

}  // namespace tracer
