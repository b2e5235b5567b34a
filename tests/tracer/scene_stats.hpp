// Test helper: what the tests compare between scenes — object counts by kind
// and the bounding box of polygon vertices and spheres (cones excluded: in
// SPD scenes every cone end carries a sphere or lies inside other objects).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <variant>

#include "tracer/scene.hpp"

namespace tracer::testing {

struct SceneStats {
  std::size_t polygons = 0, patches = 0, spheres = 0, cones = 0;
  Vec3d lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity()};
  Vec3d hi = -lo;

  void add_point(const Vec3d& p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
};

inline SceneStats scene_stats(const Scene& scene) {
  SceneStats s;
  for (const Object& o : scene.objects) {
    if (auto* p = std::get_if<Polygon>(&o.shape)) {
      ++s.polygons;
      for (const Vec3d& v : p->vertices) s.add_point(v);
    } else if (auto* pp = std::get_if<Patch>(&o.shape)) {
      ++s.patches;
      for (const Vec3d& v : pp->vertices) s.add_point(v);
    } else if (auto* sp = std::get_if<Sphere>(&o.shape)) {
      ++s.spheres;
      double r = std::abs(sp->radius);
      s.add_point(sp->center - Vec3d{r, r, r});
      s.add_point(sp->center + Vec3d{r, r, r});
    } else {
      ++s.cones;
    }
  }
  return s;
}

}  // namespace tracer::testing
