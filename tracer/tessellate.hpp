// Tessellation of analytic primitives into smooth triangles ("pp" patches
// with unit vertex normals), exactly as SPD's "-t RES" option does, so a
// tessellated built-in scene matches the SPD reference files:
//  - a sphere at resolution r: the six faces of a cube, each an r x r grid
//    at equal angles (-45..45 degrees) projected onto the sphere, each grid
//    cell two triangles: 12 r^2 triangles, counter-clockwise seen from the
//    visible side (inside, for a negative radius);
//  - a cone or cylinder at resolution r: 4 r slices around the axis, each
//    two triangles, no caps: 8 r triangles (fewer for a true cone, whose
//    zero-area triangles at the apex are dropped).
// Each object keeps its material and its place in the object order.
// tessellate() leaves spheres and cones with a negative radius (only their
// inside visible) as they are: the renderer skips their hits from outside,
// while its triangles are two-sided (render.hpp), so triangles would show the
// outside instead.
#pragma once

#include <cstdint>
#include <vector>

#include "tracer/scene.hpp"

namespace tracer {

inline constexpr int kMaxTessellation = 64;

std::vector<Patch> tessellate_sphere(const Sphere& sphere, int resolution);
std::vector<Patch> tessellate_cone(const Cone& cone, int resolution);

// How many objects tessellate(scene, resolution) would leave, counting its
// triangles as 12 r^2 a sphere and 8 r a cone (a true cone's dropped apex
// triangles included, so an upper bound): for a caller to weigh a
// tessellation before making it. No range check on the resolution.
std::uint64_t tessellated_object_count(const Scene& scene, int resolution);

// Replaces every sphere and cone of the scene (except the inside-only ones,
// see above) by its triangles. Throws
// std::invalid_argument unless 1 <= resolution <= kMaxTessellation.
void tessellate(Scene& scene, int resolution);

}  // namespace tracer
