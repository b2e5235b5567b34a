// SPD "teapot": the 32 Bezier patches of the Utah teapot (carried in the
// binary, tracer/data/utah-teapot.txt) each cut into size x size quads of two
// smooth triangles with normals from the patch derivatives, on a size x size
// checkerboard. Triangles with two vertices at a cusp (lid knob, bottom
// centre) are dropped: 64 n^2 - 8 n triangles remain.
#include <array>
#include <sstream>

#include "tracer/embedded_data.hpp"
#include "tracer/gen_spd.hpp"
#include "tracer/generators.hpp"

namespace tracer {
namespace {

struct BezierData {
  std::vector<std::array<int, 16>> patches;  // row-major 4x4 control point indices
  std::vector<Vec3d> points;
};

// The embedded file is ours and fixed; a failure here is a build defect.
BezierData read_teapot() {
  std::istringstream in{std::string(embedded::utah_teapot)};
  BezierData data;
  std::string line, word;
  std::size_t count = 0;
  auto next_data_line = [&] {
    while (std::getline(in, line))
      if (!line.empty() && line[0] != '#') return true;
    throw std::logic_error("embedded teapot data is truncated");
  };
  next_data_line();
  std::istringstream(line) >> word >> count;
  for (std::size_t i = 0; i < count && next_data_line();) {
    std::istringstream row(line);
    std::array<int, 16> p{};
    for (int& k : p) row >> k;
    data.patches.push_back(p);
    ++i;
  }
  next_data_line();
  std::istringstream(line) >> word >> count;
  for (std::size_t i = 0; i < count && next_data_line(); ++i) {
    Vec3d v;
    std::istringstream(line) >> v.x >> v.y >> v.z;
    data.points.push_back(v);
  }
  return data;
}

// Cubic Bernstein weights and their derivatives at u.
void bernstein(double u, double b[4], double db[4]) {
  double w = 1 - u;
  b[0] = w * w * w, b[1] = 3 * u * w * w, b[2] = 3 * u * u * w, b[3] = u * u * u;
  db[0] = -3 * w * w, db[1] = 3 * w * w - 6 * u * w, db[2] = 6 * u * w - 3 * u * u, db[3] = 3 * u * u;
}

// Point and normal at (s, t): s runs down the control rows, t along them; the
// normal is t-tangent x s-tangent, as SPD's teapot computes it.
void evaluate(const std::array<Vec3d, 16>& g, double s, double t, Vec3d& point, Vec3d& normal) {
  double bs[4], dbs[4], bt[4], dbt[4];
  bernstein(s, bs, dbs);
  bernstein(t, bt, dbt);
  Vec3d ds{}, dt{};
  point = {};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      point += g[r * 4 + c] * (bs[r] * bt[c]);
      ds += g[r * 4 + c] * (dbs[r] * bt[c]);
      dt += g[r * 4 + c] * (bs[r] * dbt[c]);
    }
  Vec3d n = cross(dt, ds);
  double len = length(n);
  normal = len > 0 ? n / len : Vec3d{};
}

bool at_cusp(const Vec3d& v) { return std::abs(v.x) < 1e-4 && std::abs(v.y) < 1e-4; }

// Drops triangles with two cusp vertices; gives a lone cusp vertex the axial
// normal (its derivative normal vanishes).
bool fix_cusp(Patch& tri) {
  int cusps = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!at_cusp(tri.vertices[i])) continue;
    ++cusps;
    tri.normals[i] = {0, 0, tri.vertices[i].z > 1.5 ? 1.0 : -1.0};
  }
  return cusps <= 1;
}

void add_teapot(Scene& scene, int n) {
  BezierData data = read_teapot();
  spd::add_material(scene, {1, 0.5f, 0.1f}, 0.75, 0.25, 37, 0, 0);
  for (const auto& patch : data.patches) {
    std::array<Vec3d, 16> g;
    for (int k = 0; k < 16; ++k) g[k] = data.points.at(static_cast<std::size_t>(patch[k]));
    for (int si = 0; si < n; ++si)
      for (int ti = 0; ti < n; ++ti)
        for (int tri = 0; tri < 2; ++tri) {
          Patch p{Vertices(3), std::vector<Vec3d>(3)};
          for (int k = 0; k < 3; ++k) {
            int corner = (k + tri * 2) % 4;  // quad corners 0..3, split along 0-2
            double s = double(si + (corner / 2 ? 1 : 0)) / n, t = double(ti + (corner % 3 ? 1 : 0)) / n;
            evaluate(g, s, t, p.vertices[k], p.normals[k]);
          }
          if (fix_cusp(p)) scene.objects.push_back({std::move(p), spd::current_material(scene)});
        }
  }
}

// White squares where (i + j) is odd, then grey ones, spanning [-4, 4]^2.
void add_checkerboard(Scene& scene, int n) {
  for (int parity : {1, 0}) {
    float grey = parity ? 1.0f : 0.5f;
    spd::add_material(scene, {grey, grey, grey}, 0.5, 0.5, 30, 0, 0);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if ((i + j) % 2 != parity) continue;
        auto x = [&](int k) { return 4 * (2.0 * k / n - 1); };
        spd::add_polygon(scene, {{x(i), x(j), 0}, {x(i + 1), x(j), 0}, {x(i + 1), x(j + 1), 0}, {x(i), x(j + 1), 0}});
      }
  }
}

}  // namespace

Scene generate_teapot(int size) {
  // Size 1 has more degenerate triangles than SPD's count formula allows for.
  spd::check_size("teapot", size, 2, 64);
  Scene scene;
  spd::begin_scene(scene, {4.86, 7.2, 5.4}, {0, 0, 0}, {0, 0, 1}, 1.0);
  scene.lights.push_back({{-3.1, 9.8, 12.1}});
  scene.lights.push_back({{11.3, 5.1, 8.8}});
  add_checkerboard(scene, size);
  add_teapot(scene, size);
  return scene;
}

}  // namespace tracer
