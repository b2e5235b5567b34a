// SPD generators built from repeated parts: gears (a cube of 36-tooth gears,
// each two concave 144-gons and 144 side rectangles, on a reflective floor)
// and tree (Aono & Kunii's branching tree of cones with spheres at the
// joints, on a green field). Objects come out in the SPD programs' order.
#include <algorithm>
#include <cmath>

#include "tracer/gen_spd.hpp"
#include "tracer/generators.hpp"

namespace tracer {
namespace {

using spd::kPi;
constexpr int kTeeth = 36;

// One face outline of a gear: four points per tooth. The first three points
// span a convex corner, as NFF requires.
Vertices gear_outline(const Vec3d& center, double offset, double outer, double inner, double z, int sense) {
  const double tooth = sense * 2 * kPi / kTeeth;
  Vertices pts;
  for (int t = 0; t < kTeeth; ++t) {
    double a = offset + sense * 2 * kPi * t / kTeeth;
    pts.push_back(spd::rotate_z({outer, 0, z}, a - 0.19 * tooth) + center);
    pts.push_back(spd::rotate_z({outer, 0, z}, a + 0.19 * tooth) + center);
    pts.push_back(spd::rotate_z({inner, 0, z}, a + 0.3 * tooth) + center);
    pts.push_back(spd::rotate_z({inner, 0, z}, a + 0.7 * tooth) + center);
  }
  return pts;
}

void add_gear(Scene& scene, const Vec3d& center, double offset, double outer, double inner, double thickness) {
  const Vertices top = gear_outline(center, offset, outer, inner, 0, +1);
  spd::add_polygon(scene, top);
  for (std::size_t i = 0; i < top.size(); ++i) {
    const Vec3d& a = top[i];
    const Vec3d& b = top[(i + 1) % top.size()];
    Vec3d down{0, 0, thickness};
    spd::add_polygon(scene, {a, a - down, b - down, b});
  }
  spd::add_polygon(scene, gear_outline(center, offset, outer, inner, -thickness, -1));
}

double fraction(double x) { return x - std::floor(x); }

// A branch's frame: world = m * local + t (m column-major by axis images).
struct Frame {
  Vec3d ex{1, 0, 0}, ey{0, 1, 0}, ez{0, 0, 1}, t{};
  Vec3d apply(const Vec3d& p) const { return ex * p.x + ey * p.y + ez * p.z + t; }
  Vec3d apply_vector(const Vec3d& v) const { return ex * v.x + ey * v.y + ez * v.z; }
};

// Child frame: the local step (tilt about X, turn about Z, contract, lift to
// the parent's tip) followed by the parent's frame.
Frame branch_frame(const Frame& parent, double tilt_deg, double turn_deg, double contraction) {
  auto local = [&](const Vec3d& v) { return spd::rotate_z(spd::rotate_x(v, tilt_deg * kPi / 180), turn_deg * kPi / 180) * contraction; };
  Frame f;
  f.ex = parent.apply_vector(local({1, 0, 0}));
  f.ey = parent.apply_vector(local({0, 1, 0}));
  f.ez = parent.apply_vector(local({0, 0, 1}));
  f.t = parent.apply({0, 0, 1});
  return f;
}

void grow_tree(Scene& scene, const Frame& frame, double scale, int depth) {
  double base_r = scale * 0.15, apex_r = base_r * 0.67;
  Vec3d base = frame.apply({0, 0, 0}), apex = frame.apply({0, 0, 1});
  scene.objects.push_back({Cone{base, base_r, apex, apex_r}, spd::current_material(scene)});
  spd::add_sphere(scene, apex, apex_r);
  if (depth == 0) return;
  grow_tree(scene, branch_frame(frame, 40, 90, 0.65), scale * 0.67, depth - 1);
  grow_tree(scene, branch_frame(frame, 25, 140 + 90, 0.70), scale * 0.67, depth - 1);
}

}  // namespace

Scene generate_gears(int size) {
  spd::check_size("gears", size, 1, 12);
  Scene scene;
  spd::begin_scene(scene, {-1.1, -2.1, 2.6}, {0, 0, 0}, {0, 0, 1}, 1.0);
  for (Vec3d p : {Vec3d{2, 4, 4}, Vec3d{-2, 4, 3}, Vec3d{2, -2.5, 2.5}, Vec3d{-1, -4, 2}, Vec3d{-1.111, -2.121, 2.626}})
    scene.lights.push_back({p});
  spd::add_material(scene, {1, 0.85f, 0.7f}, 0.3, 0.6, 37, 0, 0);
  spd::add_polygon(scene, {{2, 2, 0}, {-2, 2, 0}, {-2, -2, 0}, {2, -2, 0}});
  const double edge_diff = 0.1;
  double outer = 1.0 / (size - (size - 1) * edge_diff / 2);
  double step = outer * (2 - edge_diff), thickness = std::min(0.1, 1.0 / (2.0 * size));
  for (int iz = 0; iz < size; ++iz)
    for (int iy = 0; iy < size; ++iy)
      for (int ix = 0; ix < size; ++ix) {
        Vec3d center{-1 + outer + ix * step, -1 + outer + iy * step, 1 - double(iz) / size};
        double c[3] = {0.01 + fraction((ix * 3 + iy * 2 + iz + 1) * 5.0 / 7), 0.01 + fraction((iy * 3 + iz * 2 + ix + 1) * 3.0 / 7),
                       0.01 + fraction((iz * 3 + ix * 2 + iy + 1) * 2.0 / 7)};
        double m = std::max({c[0], c[1], c[2]});
        Color color{float(c[0] / m), float(c[1] / m), float(c[2] / m)};
        if ((ix * 4 + iy * 2 + iz) % 5 == 0) spd::add_material(scene, color, 0.2, 0, 0, 0.8, 1.1);
        else spd::add_material(scene, color, 1, 0, 0, 0, 0);
        double offset = kPi * ((ix + iy + iz) % 2) / kTeeth;
        add_gear(scene, center, offset, 0.995 * outer, (1 - edge_diff) * outer, thickness);
      }
  return scene;
}

Scene generate_tree(int size) {
  spd::check_size("tree", size, 1, 14);
  Scene scene;
  spd::begin_scene(scene, {4.5, 0.4, 2.0}, {0, 0, 1.5}, {0, 0, 1}, 1.0);
  for (Vec3d p : {Vec3d{-5, 5, 50}, Vec3d{30, -30, 30}, Vec3d{-40, -30, 20}, Vec3d{10, 30, 40}, Vec3d{-30, 40, 10},
                  Vec3d{50, 25, 20}, Vec3d{-10, -60, 30}})
    scene.lights.push_back({p});
  spd::add_material(scene, {0.2f, 0.7f, 0.2f}, 1, 0, 0, 0, 0);
  spd::add_polygon(scene, {{50, 50, 0}, {-50, 50, 0}, {-50, -50, 0}, {50, -50, 0}});
  spd::add_material(scene, {0.55f, 0.4f, 0.2f}, 1, 0, 0, 0, 0);
  grow_tree(scene, Frame{}, 1.0, size);
  return scene;
}

}  // namespace tracer
