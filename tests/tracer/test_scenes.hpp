// Scenes built in code for the core tracer tests (fixed seeds).
#pragma once

#include <random>

#include "tracer/scene.hpp"

namespace tracer::testing {

// A few hundred random small triangles and spheres in the unit cube.
inline Scene random_scene(unsigned seed, int triangles, int spheres) {
  Scene s;
  s.name = "random";
  s.materials.push_back({});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-1, 1), off(-0.15, 0.15), rad(0.02, 0.1);
  for (int i = 0; i < triangles; ++i) {
    const Vec3d c{pos(rng), pos(rng), pos(rng)};
    Polygon p;
    for (int k = 0; k < 3; ++k) p.vertices.push_back(c + Vec3d{off(rng), off(rng), off(rng)});
    s.objects.push_back({p, 0});
  }
  for (int i = 0; i < spheres; ++i)
    s.objects.push_back({Sphere{{pos(rng), pos(rng), pos(rng)}, rad(rng)}, 0});
  return s;
}

// Every kind of primitive and material: a floor, a non-convex polygon, a
// smooth patch, mirror, glass and inside-only spheres, a cone and a cylinder.
inline Scene showcase_scene(int size) {
  Scene s;
  s.name = "showcase";
  s.camera = {{0, -6, 2.5}, {0, 0, 0.6}, {0, 0, 1}, 40.0, 0.01, size, size};
  s.background = {0.1f, 0.2f, 0.4f};
  s.lights = {{{4, -3, 6}, {1, 1, 1}}, {{-3, -4, 5}, {1, 1, 1}}};
  s.materials = {{{0.9f, 0.8f, 0.6f}, 0.8, 0.0, 0, 0, 1},
                 {{1, 0.3f, 0.3f}, 0.5, 0.5, 30, 0, 1},
                 {{1, 1, 1}, 0.1, 0.1, 50, 0.85, 1.5},
                 {{0.3f, 1, 0.4f}, 0.7, 0.3, 10, 0, 1}};
  s.objects.push_back({Polygon{{{-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}}}, 0});
  s.objects.push_back({Polygon{{{1, 1, 0.01}, {2.5, 1, 0.01}, {2.5, 1.4, 0.8}, {1.8, 1.2, 0.4},
                                {1.4, 1.4, 0.8}, {1, 1.4, 0.8}}}, 3});
  s.objects.push_back({Patch{{{-2.5, 1, 0}, {-1, 1, 0}, {-1.7, 1, 1.5}},
                             {{-0.7, -0.7, 0}, {0.7, -0.7, 0}, {0, -0.7, 0.7}}}, 3});
  s.objects.push_back({Sphere{{-0.9, 0, 0.8}, 0.8}, 1});
  s.objects.push_back({Sphere{{0.9, -0.8, 0.6}, 0.6}, 2});
  s.objects.push_back({Sphere{{0.3, 2.0, 0.7}, -0.7}, 3});
  s.objects.push_back({Cone{{2.2, 0, 0}, 0.5, {2.2, 0, 1.4}, 0.1}, 1});
  s.objects.push_back({Cone{{-2.5, -0.5, 0}, 0.3, {-2.5, -0.5, 1.0}, 0.3}, 3});
  return s;
}

}  // namespace tracer::testing
