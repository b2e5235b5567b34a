// Internal to the generators: the pieces every SPD program shares — the
// standard header (sky-blue background, 45 degree view, 512x512), SPD's
// material convention (a highlight angle turned into a Phong exponent), and
// right-handed rotations (positive angles turn counter-clockwise seen from
// the tip of the axis, as SPD's matrices do).
#pragma once

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "tracer/scene.hpp"

namespace tracer::spd {

inline constexpr double kPi = std::numbers::pi;

// Background, viewpoint and image size every SPD program writes first.
inline void begin_scene(Scene& scene, const Vec3d& from, const Vec3d& at, const Vec3d& up, double hither) {
  scene.background = {0.078f, 0.361f, 0.753f};
  scene.camera = Camera{from, at, up, 45.0, hither, 512, 512};
}

// SPD's lib_output_color for NFF: the highlight half-angle ang (degrees)
// becomes the exponent at which cos^n(ang) = 1/2; zero means a mirror-sharp
// highlight, written as 100000.
inline void add_material(Scene& scene, Color color, double kd, double ks, double ang, double t, double ior) {
  double c = std::cos(ang * kPi / 180.0);
  double shine = (ang <= 0 || c >= 1) ? 100000.0 : std::min(100000.0, std::log(0.5) / std::log(c));
  scene.materials.push_back(Material{color, kd, ks, shine, t, ior});
}

inline std::uint32_t current_material(const Scene& scene) {
  return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

inline void add_polygon(Scene& scene, Vertices vertices) {
  scene.objects.push_back({Polygon{std::move(vertices)}, current_material(scene)});
}

inline void add_sphere(Scene& scene, const Vec3d& center, double radius) {
  scene.objects.push_back({Sphere{center, radius}, current_material(scene)});
}

// Rodrigues' rotation of v about the unit vector axis by angle radians.
inline Vec3d rotate(const Vec3d& v, const Vec3d& axis, double angle) {
  double c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1 - c));
}

inline Vec3d rotate_x(const Vec3d& v, double a) {
  return {v.x, v.y * std::cos(a) - v.z * std::sin(a), v.y * std::sin(a) + v.z * std::cos(a)};
}
inline Vec3d rotate_y(const Vec3d& v, double a) {
  return {v.x * std::cos(a) + v.z * std::sin(a), v.y, -v.x * std::sin(a) + v.z * std::cos(a)};
}
inline Vec3d rotate_z(const Vec3d& v, double a) {
  return {v.x * std::cos(a) - v.y * std::sin(a), v.x * std::sin(a) + v.y * std::cos(a), v.z};
}

inline void check_size(const char* name, int size, int lo, int hi) {
  if (size < lo || size > hi)
    throw std::invalid_argument(std::string(name) + ": size " + std::to_string(size) + " out of range " +
                                std::to_string(lo) + ".." + std::to_string(hi));
}

}  // namespace tracer::spd
