// SPD generators built from flat polygons and spheres: tetra (recursive
// tetrahedra), mount (Carpenter's fractal mountain with SPD's own hash and
// Gaussian generator, so the surface matches the reference files), balls
// (the sphereflake) and rings (dodecahedral rings of cylinders and spheres).
// Objects come out in the SPD programs' order.
#include <algorithm>
#include <cmath>

#include "tracer/gen_spd.hpp"
#include "tracer/generators.hpp"

namespace tracer {
namespace {

using spd::kPi;

// Tetrahedra inside the cube center +- half; recursion on the four corner
// sub-tetrahedra whose corners satisfy x*y*z = +1.
void tetra_level(Scene& scene, int depth, const Vec3d& center, double half) {
  std::vector<Vec3d> corners;
  for (int x = -1; x <= 1; x += 2)
    for (int y = -1; y <= 1; y += 2)
      for (int z = -1; z <= 1; z += 2)
        if (x * y * z == 1) corners.push_back(center + Vec3d{double(x), double(y), double(z)} * (depth <= 1 ? half : half / 2));
  if (depth > 1) {
    for (const Vec3d& c : corners) tetra_level(scene, depth - 1, c, half / 2);
    return;
  }
  // Faces 0 1 2, 3 2 1, 2 3 0, 1 0 3: outward and counter-clockwise.
  for (int face = 0; face < 4; ++face) {
    int a = face % 4, b = (face + 1) % 4, c = (face + 2) % 4;
    if (face % 2 == 1) std::swap(a, c);
    spd::add_polygon(scene, {corners[a], corners[b], corners[c]});
  }
}

// SPD mount's original (repetitive, but reference-defining) hash of a grid
// point, and its Numerical Recipes style Gaussian deviate seeded by it.
long mount_hash(long a, long b, int size) {
  auto ua = static_cast<unsigned long>(a), ub = static_cast<unsigned long>(b);
  return static_cast<long>(((ua << (23 - size)) + (ub << (15 - size)) + (ua << (7 - size))) & 0xffff);
}

double spd_gauss(long seed) {
  const long m = 134456, ia = 8121, ic = 28411;
  long ix1, ix2 = seed;
  double v1, v2, r;
  do {
    ix1 = (ic + ix2 * ia) % m;
    ix2 = (ic + ix1 * ia) % m;
    v1 = ix1 * 2.0 / m - 1.0;
    v2 = ix2 * 2.0 / m - 1.0;
    r = v1 * v1 + v2 * v2;
  } while (r >= 1.0);
  return v1 * std::sqrt(-2.0 * std::log(r) / r);
}

struct Mountain {
  Scene& scene;
  int size;
  double cells;      // grid cells per side, 2^size
  double roughness;  // from fractal dimension 2.2

  double noise(long x, long y) const { return spd_gauss(21 + mount_hash(x, y, size)); }

  // Corner heights ll, lr, ur, ul of the square of `width` cells at (x, y).
  void grow(int width, long x, long y, double ll, double lr, double ur, double ul) {
    if (width == 1) return emit(x, y, ll, lr, ur, ul);
    int h = width / 2;
    double rise = h * 2.0 / cells * roughness;
    double lower = (ll + lr) / 2 + rise * noise(x + h, y);
    double right = (lr + ur) / 2 + rise * noise(x + width, y + h);
    double upper = (ur + ul) / 2 + rise * noise(x + h, y + width);
    double left = (ul + ll) / 2 + rise * noise(x, y + h);
    double middle = (ll + lr + ur + ul) / 4 + 1.4142136 * rise * noise(x + h, y + h);
    grow(h, x, y, ll, lower, middle, left);
    grow(h, x + h, y, lower, lr, right, middle);
    grow(h, x + h, y + h, middle, right, ur, upper);
    grow(h, x, y + h, left, middle, upper, ul);
  }

  void emit(long x, long y, double ll, double lr, double ur, double ul) {
    double lx = -1 + x * 2.0 / cells, rx = -1 + (x + 1) * 2.0 / cells;
    double ly = -1 + y * 2.0 / cells, uy = -1 + (y + 1) * 2.0 / cells;
    Vec3d q[4] = {{lx, ly, ll}, {rx, ly, lr}, {rx, uy, ur}, {lx, uy, ul}};
    spd::add_polygon(scene, {q[0], q[1], q[2]});
    spd::add_polygon(scene, {q[2], q[3], q[0]});
  }
};

// A pyramid of four glass spheres of radius r resting around center.
void crystal_spheres(Scene& scene, const Vec3d& center, double r) {
  Vec3d top{0, 0, r * std::sqrt(1.5)};
  spd::add_sphere(scene, center + top, r);
  Vec3d side = spd::rotate(top, normalize(Vec3d{1, 1, 0}), std::acos(-1.0 / 3.0));
  for (int i = 0; i < 3; ++i) spd::add_sphere(scene, spd::rotate_z(side, i * 2 * kPi / 3) + center, r);
}

// The nine child directions of a sphereflake node (three trios about +Z).
std::vector<Vec3d> flake_directions() {
  double d = 1 / std::sqrt(2.0);
  Vec3d trio[3] = {{d, d, 0}, {d, 0, -d}, {0, d, -d}};
  Vec3d axis = normalize(Vec3d{1, -1, 0});
  double tilt = std::asin(2 / std::sqrt(6.0));
  std::vector<Vec3d> set;
  for (int k = 0; k < 3; ++k)
    for (const Vec3d& t : trio) set.push_back(spd::rotate_z(spd::rotate(t, axis, tilt), k * 2 * kPi / 3));
  return set;
}

void flake(Scene& scene, const std::vector<Vec3d>& set, int depth, const Vec3d& c, double r, const Vec3d& dir) {
  spd::add_sphere(scene, c, r);
  if (depth == 0) return;
  // Rotation taking +Z to dir (unit up to rounding, so dir.z may miss +-1
  // where dir is along Z: the axis decides, and acos gets a clamped cosine).
  const Vec3d axis = cross(Vec3d{0, 0, 1}, dir);
  auto orient = [&](const Vec3d& v) {
    if (length(axis) == 0) return dir.z > 0 ? v : spd::rotate_y(v, kPi);
    return spd::rotate(v, normalize(axis), std::acos(std::clamp(dir.z, -1.0, 1.0)));
  };
  double scale = r * (1 + 1.0 / 3);
  for (const Vec3d& v : set) {
    Vec3d child = orient(v) * scale + c;
    flake(scene, set, depth - 1, child, r / 3, (child - c) / scale);
  }
}

// The 30 ring vertices: six pentagons joining edge midpoints of a dodecahedron.
std::vector<Vec3d> dodec_rings(double minor_radius) {
  double scale = 1 / (1 + minor_radius);
  std::vector<Vec3d> v;
  for (int i = 0; i < 5; ++i) v.push_back(Vec3d{std::cos(i * 2 * kPi / 5), std::sin(i * 2 * kPi / 5), 0} * scale);
  double x_rot = 2 * std::acos(std::cos(kPi / 3) / std::sin(kPi / 5));
  for (int p = 1; p < 6; ++p) {
    double z_rot = kPi * (2.0 * (p - 1) + 1) / 5;
    for (int i = 0; i < 5; ++i) v.push_back(spd::rotate_z(spd::rotate_x(v[i], x_rot), z_rot));
  }
  return v;
}

}  // namespace

Scene generate_tetra(int size) {
  spd::check_size("tetra", size, 1, 11);
  Scene scene;
  spd::begin_scene(scene, {1.022846, -3.177154, -2.174512}, {-0.004103, -0.004103, 0.216539},
                   {-0.816497, -0.816497, 0.816497}, 1.0);
  scene.lights.push_back({{2, -18, -5}});
  spd::add_material(scene, {1, 0.2f, 0.2f}, 1, 0, 0, 0, 0);
  scene.objects.reserve(std::size_t{1} << (2 * size));  // exactly 4^size triangles
  tetra_level(scene, size, {0, 0, 0}, 1.0);
  return scene;
}

Scene generate_mount(int size) {
  // SPD's hash shifts by (7 - size) bits: sizes above 7 are undefined there.
  spd::check_size("mount", size, 1, 7);
  Scene scene;
  spd::begin_scene(scene, {-1.6, 1.6, 1.7}, {0, 0, 0}, {0, 0, 1}, 0.01);
  scene.lights.push_back({{-100, -100, 100}});
  spd::add_material(scene, {1, 1, 1}, 0.1, 0.1, 6.7, 0.9, 1.5);
  crystal_spheres(scene, {-0.8, 0.8, 1.0}, 0.17);
  spd::add_material(scene, {0.5f, 0.45f, 0.35f}, 1, 0, 0, 0, 0);
  double ratio = 2 / std::exp(std::log(2.0) / (2.2 - 1));
  Mountain m{scene, size, double(1 << size), std::sqrt(ratio * ratio - 1)};
  m.grow(1 << size, 0, 0, 0, 0, 0, 0);
  return scene;
}

Scene generate_balls(int size) {
  spd::check_size("balls", size, 1, 5);
  Scene scene;
  spd::begin_scene(scene, {2.1, 1.3, 1.7}, {0, 0, 0}, {0, 0, 1}, 0.01);
  for (Vec3d p : {Vec3d{4, 3, 2}, Vec3d{1, -4, 4}, Vec3d{-3, 1, 5}}) scene.lights.push_back({p});
  spd::add_material(scene, {1, 0.75f, 0.33f}, 0.8, 0, 0, 0, 1);
  spd::add_polygon(scene, {{12, 12, -0.5}, {-12, 12, -0.5}, {-12, -12, -0.5}, {12, -12, -0.5}});
  spd::add_material(scene, {1, 0.9f, 0.7f}, 0.5, 0.5, 37, 0, 1);
  flake(scene, flake_directions(), size, {0, 0, 0}, 0.5, {0, 0, 1});
  return scene;
}

Scene generate_rings(int size) {
  spd::check_size("rings", size, 1, 12);
  const double radius = 0.07412, spread = 1 / std::sin(kPi / 8);
  Scene scene;
  Vec3d from{-1, -spread, 0.5};
  spd::begin_scene(scene, from, from + Vec3d{0, 1, 0}, {0, 0, 1}, 1.0);
  for (Vec3d p : {Vec3d{3, -spread, 3}, Vec3d{-4, -spread, 1}, Vec3d{2, -spread, -4}}) scene.lights.push_back({p});
  spd::add_material(scene, {1, 1, 1}, 1, 0, 0, 0, 0);
  // A backdrop just spanning the 45 degree view, plus 1%.
  double wy = spread * (size + 1), w = 1.01 * (wy - from.y) * std::tan(kPi / 8);
  spd::add_polygon(scene, {{w + from.x, wy, w + from.z}, {-w + from.x, wy, w + from.z},
                           {-w + from.x, wy, -w + from.z}, {w + from.x, wy, -w + from.z}});
  const Color ring_colors[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}, {1, 0, 1}, {1, 1, 0}};
  std::vector<Vec3d> dodec = dodec_rings(radius);
  for (int depth = 0; depth < size; ++depth)
    for (int iz = 0; iz <= depth; ++iz)
      for (int ix = 0; ix <= depth; ++ix) {
        Vec3d offset{double(2 * ix - depth), spread * (depth + 1), double(2 * iz - depth)};
        for (int e = 0; e < 30; ++e) {
          if (e % 5 == 0) spd::add_material(scene, ring_colors[e / 5], 0.5, 0.2, 37, 0, 0);
          Vec3d base = dodec[e] + offset, apex = dodec[e % 5 == 0 ? e + 4 : e - 1] + offset;
          scene.objects.push_back({Cone{base, radius, apex, radius}, spd::current_material(scene)});
          spd::add_sphere(scene, base, radius);
        }
      }
  return scene;
}

}  // namespace tracer
