// Pixels against an oracle that shares no code with the renderer's shading.
// Each scene here is a few spheres and large flat quads, simple enough that
// every ray of a pixel can be followed in closed form; the expected colour is
// worked out in double precision from the geometry and from the shading model
// as render.hpp states it: per light of intensity 1/sqrt(number of lights),
// Kd * colour * (N.L) + Ks * (R.V)^Shine when nothing lies between the point
// and the light, no ambient term; a mirror ray weighted Ks, a refracted ray
// weighted T (Snell's law, the material's index inside, 1 outside); the
// background for a ray that meets nothing; no clamping. The camera is the one
// camera.hpp defines (the centres of the first and last columns angle/2 either
// side of the view axis, x right, y down), its frame worked out by hand.
//
// The renderer computes in single precision: a colour differs from the
// oracle's by a few float roundings per operation, about 1e-6 on colours of
// order one, which the specular power multiplies by its exponent (4e-6 is
// the most seen here, under an exponent of 50), so a pixel matches within
// kTolerance (absolute). A wrong term moves pixels by far more: a Phong
// exponent off by one, the least of the errors tried, by up to 7e-3.
// A ray that passes within a hair of a silhouette, of the seam between a
// quad's two triangles or of a shadow's border could go either way in single
// precision; the oracle leaves those pixels out, and each test checks that it
// still compares nearly all of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "tracer/render.hpp"

namespace tracer {
namespace {

using V = Vec3d;  // points, directions and colours (x, y, z as red, green, blue)

constexpr double kTolerance = 2e-5;
constexpr double kHair = 1e-4;  // world units: a ray nearer than this to an outline is not called
constexpr double kNever = std::numeric_limits<double>::infinity();

V rgb(const Color& c) { return {c.r, c.g, c.b}; }
V mul(const V& a, const V& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

// A camera with its frame worked out by hand from from, at and up.
struct View {
  Camera camera;
  V forward, right, up;  // unit and orthogonal
};

// The eye ray's direction through the centre of pixel (x, y).
V eye_direction(const View& v, int x, int y) {
  const Camera& c = v.camera;
  const double half = std::tan(c.angle_deg / 2 * std::numbers::pi / 180);
  const double per_pixel = half / ((std::max(c.width, c.height) - 1) / 2.0);
  return v.forward + v.right * ((x - (c.width - 1) / 2.0) * per_pixel) -
         v.up * ((y - (c.height - 1) / 2.0) * per_pixel);
}

// Where the ray o + t d, 0 < t < t_max, first meets a shape; `doubtful` when
// it passes within a hair of the shape's outline.
struct Meet {
  std::optional<double> t;
  bool doubtful = false;
};

Meet meet_sphere(const V& o, const V& d, const V& centre, double radius, double t_max = kNever) {
  const V oc = o - centre;
  const double s = -dot(oc, d) / dot(d, d);  // where the line comes closest to the centre
  const V closest = oc + d * s;
  const double miss_by = length(closest) - radius;
  Meet m;
  m.doubtful = std::abs(miss_by) < kHair && s > 0 && s < t_max;
  if (miss_by >= 0) return m;
  const double half_chord = std::sqrt((radius * radius - dot(closest, closest)) / dot(d, d));
  for (double t : {s - half_chord, s + half_chord}) {
    if (t > 0 && t < t_max) {
      m.t = t;
      break;
    }
  }
  return m;
}

// A planar convex quad, counter-clockwise seen from the side `normal` points
// to; the tracer cuts it into two triangles along one of its diagonals.
struct Quad {
  std::array<V, 4> v;
  V normal;  // unit
};

Meet meet_quad(const V& o, const V& d, const Quad& q, double t_max = kNever) {
  Meet m;
  const double along = dot(d, q.normal);
  if (along == 0) return m;
  const double t = dot(q.v[0] - o, q.normal) / along;
  if (!(t > 0 && t < t_max)) return m;
  const V p = o + d * t;
  // Distance from p to the line through a and b, positive on the quad's side of an edge.
  const auto side = [&](const V& a, const V& b) { return dot(cross(b - a, p - a), q.normal) / length(b - a); };
  double inside = kNever;
  for (int i = 0; i < 4; ++i) inside = std::min(inside, side(q.v[i], q.v[(i + 1) % 4]));
  const double seam = std::min(std::abs(side(q.v[0], q.v[2])), std::abs(side(q.v[1], q.v[3])));
  m.doubtful = std::abs(inside) < kHair || (inside > 0 && seam < kHair);
  if (inside > 0) m.t = t;
  return m;
}

// Whether something lies on the segment from `origin` to the light at
// `lamp`; nullopt when a shape's outline passes within a hair of it.
using Hidden = std::function<std::optional<bool>(const V& origin, const V& lamp)>;

// The two parts of the light a surface point sends to the eye.
struct Direct {
  V diffuse{};
  V specular{};
  V sum() const { return diffuse + specular; }
};

// Per light that faces the point and that nothing hides: Kd * colour * (N.L)
// and Ks * (R.V)^Shine, R the direction to the light mirrored about N, V the
// unit direction to the eye. Shadow rays leave from p lifted `eps` (the
// database's self-intersection offset) along n; n faces the eye. nullopt
// when the light grazes the surface or a shadow's border, so single
// precision may decide otherwise.
std::optional<Direct> direct(const V& p, const V& n, const V& to_eye, const Material& m,
                             const std::vector<Light>& lights, double eps, const Hidden& hidden) {
  const double intensity = 1 / std::sqrt(static_cast<double>(lights.size()));
  const V origin = p + n * eps;
  Direct c;
  for (const Light& light : lights) {
    const V l = normalize(light.position - origin);
    const double n_dot_l = dot(n, l);
    if (std::abs(n_dot_l) < 1e-6) return std::nullopt;
    if (n_dot_l < 0) continue;
    const std::optional<bool> in_shadow = hidden(origin, light.position);
    if (!in_shadow) return std::nullopt;
    if (*in_shadow) continue;
    const V lamp = rgb(light.color) * intensity;
    c.diffuse += mul(rgb(m.color), lamp) * (m.kd * n_dot_l);
    const double r_dot_v = dot(n * (2 * n_dot_l) - l, to_eye);
    if (m.ks > 0 && r_dot_v > 0) c.specular += lamp * (m.ks * std::pow(r_dot_v, m.shine));
  }
  return c;
}

const Hidden nothing_hides = [](const V&, const V&) { return std::optional<bool>(false); };

struct Rendered {
  std::vector<Color> pixels;
  double epsilon = 0;
};

Rendered render(const Scene& scene) {
  const Database db = build_database(scene);
  InMemoryPageSource pages(db);
  RayStats stats;
  return {render_frame(db.header, pages, {}, stats), db.header.epsilon};
}

// Compares every pixel the oracle calls; returns how many it called.
int expect_oracle(const std::vector<Color>& image, const Camera& camera,
                  const std::function<std::optional<V>(int x, int y)>& oracle) {
  int called = 0, wrong = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const std::optional<V> want = oracle(x, y);
      if (!want) continue;
      ++called;
      const Color got = image[static_cast<std::size_t>(y) * camera.width + x];
      const double off = std::max({std::abs(got.r - want->x), std::abs(got.g - want->y), std::abs(got.b - want->z)});
      if (off <= kTolerance) continue;
      if (++wrong <= 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): rendered (" << got.r << ", " << got.g << ", " << got.b
                      << "), expected (" << want->x << ", " << want->y << ", " << want->z << ")";
    }
  }
  EXPECT_EQ(wrong, 0) << "pixels unlike the oracle's";
  return called;
}

// A square in the plane z = height, counter-clockwise seen from above, normal
// +z (or the same corners the other way round, normal -z); turned a little, so
// that the seam between its triangles runs along no row, column or diagonal
// of pixels.
Quad quad_at(double height, double size, bool facing_up = true) {
  Quad q{{V{-size, -0.9 * size, height}, V{0.9 * size, -size, height}, V{size, 0.9 * size, height},
          V{-0.9 * size, size, height}},
         {0, 0, 1}};
  if (!facing_up) {
    std::reverse(q.v.begin(), q.v.end());
    q.normal = {0, 0, -1};
  }
  return q;
}

Polygon polygon(const Quad& q) { return Polygon{{q.v[0], q.v[1], q.v[2], q.v[3]}}; }

// One sphere lit by two coloured lights, over a background: Lambert and Phong
// terms of both lights at the sphere's points (each light of intensity
// 1/sqrt(2)); the mirror ray of every point leaves the convex sphere and meets
// nothing, so it brings back the background weighted Ks; rays that miss give
// the background exactly. The camera's up is not perpendicular to the view.
TEST(Oracle, LitSphereHasItsLambertAndPhongTerms) {
  Scene scene;
  scene.camera = {{0, 0, 6}, {0, 0, 0}, {0, 1, 0.5}, 30.0, 1e-3, 32, 24};
  // Looking down -z; up's part along the view is dropped, and right = forward x up.
  const View view{scene.camera, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
  scene.background = {0.1f, 0.2f, 0.3f};
  scene.lights = {{{4, 5, 6}, {1, 0.9f, 0.8f}}, {{-5, 1, 3}, {0.5f, 0.6f, 1}}};
  const Material shiny{{0.9f, 0.5f, 0.3f}, 0.6, 0.35, 12, 0, 1};
  scene.materials = {shiny};
  const V centre{0.3, -0.2, 0};
  const double radius = 1;
  scene.objects.push_back({Sphere{centre, radius}, 0});
  const Rendered r = render(scene);

  int background = 0, sphere = 0, highlight = 0, one_light = 0;
  const int called = expect_oracle(r.pixels, scene.camera, [&](int x, int y) -> std::optional<V> {
    const V d = eye_direction(view, x, y);
    const Meet m = meet_sphere(view.camera.from, d, centre, radius);
    if (m.doubtful) return std::nullopt;
    if (!m.t) {
      ++background;
      return rgb(scene.background);
    }
    const V p = view.camera.from + d * *m.t;
    const V n = (p - centre) / radius;
    // Alone, the sphere hides no light from a point that faces it.
    const auto lit = direct(p, n, -normalize(d), shiny, scene.lights, r.epsilon, nothing_hides);
    if (!lit) return std::nullopt;
    ++sphere;
    highlight += lit->specular.x > 0.05;
    one_light += (dot(n, scene.lights[0].position - p) > 0) != (dot(n, scene.lights[1].position - p) > 0);
    return lit->sum() + rgb(scene.background) * shiny.ks;
  });
  EXPECT_GE(called, 32 * 24 - 4);
  EXPECT_GT(background, 50);
  EXPECT_GT(sphere, 200);
  EXPECT_GT(highlight, 3);
  EXPECT_GT(one_light, 20);
  // A ray that meets nothing returns the background itself, to the last bit.
  EXPECT_EQ(r.pixels.front(), scene.background);
  EXPECT_EQ(r.pixels.back(), scene.background);
}

// A floor seen from straight above, a sphere over it and two white lights:
// where the sphere hides one light from the floor only the other one's
// Lambert term is left (no ambient), and the sphere is lit by both.
TEST(Oracle, ShadowOfASphereLeavesOnlyTheOtherLight) {
  Scene scene;
  scene.camera = {{0, 0, 8}, {0, 0, 0}, {0, 1, 0}, 40.0, 1e-3, 28, 28};
  const View view{scene.camera, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
  scene.background = {0.05f, 0.05f, 0.05f};
  scene.lights = {{{3, 2, 5}, {1, 1, 1}}, {{-4, -1, 4}, {1, 1, 1}}};
  const Material floor_material{{0.8f, 0.7f, 0.6f}, 0.9, 0, 0, 0, 1};
  const Material ball_material{{0.3f, 0.6f, 0.9f}, 0.8, 0, 0, 0, 1};
  scene.materials = {floor_material, ball_material};
  const Quad floor = quad_at(0, 9);
  const V centre{0.4, 0.2, 1.2};
  const double radius = 0.7;
  scene.objects.push_back({polygon(floor), 0});
  scene.objects.push_back({Sphere{centre, radius}, 1});
  const Rendered r = render(scene);

  // Only the sphere can come between the floor and a light; nothing can come between the sphere
  // and a light, both above the floor.
  const Hidden by_ball = [&](const V& origin, const V& lamp) -> std::optional<bool> {
    const Meet m = meet_sphere(origin, lamp - origin, centre, radius, 1);
    if (m.doubtful) return std::nullopt;
    return m.t.has_value();
  };
  int shadowed[2] = {0, 0}, fully_lit_floor = 0, ball = 0;
  const int called = expect_oracle(r.pixels, scene.camera, [&](int x, int y) -> std::optional<V> {
    const V d = eye_direction(view, x, y);
    const V from = view.camera.from;
    const Meet to_ball = meet_sphere(from, d, centre, radius), to_floor = meet_quad(from, d, floor);
    if (to_ball.doubtful || to_floor.doubtful) return std::nullopt;
    EXPECT_TRUE(to_floor.t) << "the floor fills the view";
    if (to_ball.t) {  // above the floor, so in front of it
      const V p = from + d * *to_ball.t;
      const auto lit = direct(p, (p - centre) / radius, -normalize(d), ball_material, scene.lights, r.epsilon,
                              nothing_hides);
      if (!lit) return std::nullopt;
      ++ball;
      return lit->sum();
    }
    const V p = from + d * *to_floor.t;
    const auto lit = direct(p, floor.normal, -normalize(d), floor_material, scene.lights, r.epsilon, by_ball);
    if (!lit) return std::nullopt;
    bool any = false;
    for (int k = 0; k < 2; ++k) {
      const bool hidden = *by_ball(p + floor.normal * r.epsilon, scene.lights[k].position);
      shadowed[k] += hidden;
      any = any || hidden;
    }
    fully_lit_floor += !any;
    return lit->sum();
  });
  EXPECT_GE(called, 28 * 28 - 8);
  EXPECT_GT(shadowed[0], 10);
  EXPECT_GT(shadowed[1], 10);
  EXPECT_GT(fully_lit_floor, 300);
  EXPECT_GT(ball, 30);
}

// A mirror (Kd 0, Ks 0.8) fills the view behind a red sphere; a light between
// them. A mirror pixel is the light's specular highlight plus 0.8 times what
// its mirror ray meets: the Lambert-lit back of the sphere, or the background.
TEST(Oracle, MirrorShowsTheSphereAndTheBackground) {
  Scene scene;
  scene.camera = {{0.5, 0.3, 7}, {0.5, 0.3, 0}, {0, 1, 0}, 36.0, 1e-3, 26, 26};
  const View view{scene.camera, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
  scene.background = {0.2f, 0.25f, 0.3f};
  scene.lights = {{{1.5, 2.5, -0.5}, {1, 1, 1}}};
  const Material mirror_material{{1, 1, 1}, 0, 0.8, 50, 0, 1};
  const Material ball_material{{0.9f, 0.2f, 0.1f}, 0.9, 0, 0, 0, 1};
  scene.materials = {mirror_material, ball_material};
  const Quad mirror = quad_at(-2, 8);
  const V centre{-1.5, -0.3, 0.5};
  const double radius = 0.6;
  scene.objects.push_back({polygon(mirror), 0});
  scene.objects.push_back({Sphere{centre, radius}, 1});
  const Rendered r = render(scene);

  const Hidden by_ball = [&](const V& origin, const V& lamp) -> std::optional<bool> {
    const Meet m = meet_sphere(origin, lamp - origin, centre, radius, 1);
    if (m.doubtful) return std::nullopt;
    return m.t.has_value();
  };
  const Hidden by_mirror = [&](const V& origin, const V& lamp) -> std::optional<bool> {
    const Meet m = meet_quad(origin, lamp - origin, mirror, 1);
    if (m.doubtful) return std::nullopt;
    return m.t.has_value();
  };
  // The sphere's colour seen along d from o, or nullopt if d misses it (or doubtful: *doubtful set).
  const auto ball_seen = [&](const V& o, const V& d, bool& doubtful) -> std::optional<V> {
    const Meet m = meet_sphere(o, d, centre, radius);
    doubtful = m.doubtful;
    if (!m.t || doubtful) return std::nullopt;
    const V p = o + d * *m.t;
    const auto lit = direct(p, (p - centre) / radius, -normalize(d), ball_material, scene.lights, r.epsilon, by_mirror);
    doubtful = !lit;
    if (!lit) return std::nullopt;
    return lit->sum();  // Ks 0: no mirror ray
  };
  int ball = 0, ball_in_mirror = 0, background_in_mirror = 0, highlight = 0;
  const int called = expect_oracle(r.pixels, scene.camera, [&](int x, int y) -> std::optional<V> {
    const V d = eye_direction(view, x, y);
    const V from = view.camera.from;
    bool doubtful = false;
    if (const auto c = ball_seen(from, d, doubtful)) {  // the sphere is in front of the mirror
      ++ball;
      return *c;
    }
    const Meet to_mirror = meet_quad(from, d, mirror);
    if (doubtful || to_mirror.doubtful) return std::nullopt;
    EXPECT_TRUE(to_mirror.t) << "the mirror fills the view";
    const V p = from + d * *to_mirror.t;
    const auto lit = direct(p, mirror.normal, -normalize(d), mirror_material, scene.lights, r.epsilon, by_ball);
    if (!lit) return std::nullopt;
    highlight += lit->specular.x > 0.05;
    // The mirror ray: d mirrored in the plane z = -2, from just in front of it.
    const V u = normalize(d);
    const auto reflected = ball_seen(p + mirror.normal * r.epsilon, {u.x, u.y, -u.z}, doubtful);
    if (doubtful) return std::nullopt;
    ++(reflected ? ball_in_mirror : background_in_mirror);
    return lit->sum() + reflected.value_or(rgb(scene.background)) * mirror_material.ks;
  });
  EXPECT_GE(called, 26 * 26 - 8);
  EXPECT_GT(ball, 20);
  EXPECT_GT(ball_in_mirror, 8);
  EXPECT_GT(background_in_mirror, 300);
  EXPECT_GT(highlight, 2);
}

// A glass slab (T 0.9, index 1.5, Kd = Ks = 0) between the eye and a lit wall:
// a ray bends towards the normal going in, back to its first direction coming
// out, displaced sideways, and brings back 0.9 * 0.9 of the wall's Lambert
// term where it lands. The glass's own colour tints nothing.
TEST(Oracle, SlabRefractsTheWallBehindIt) {
  Scene scene;
  scene.camera = {{0.2, -0.1, 6}, {0.2, -0.1, 0}, {0, 1, 0}, 40.0, 1e-3, 24, 24};
  const View view{scene.camera, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
  scene.background = {0.3f, 0.3f, 0.3f};
  scene.lights = {{{0.5, 0.8, -1.2}, {1, 1, 1}}};
  const Material glass{{0.5f, 0.7f, 0.9f}, 0, 0, 0, 0.9, 1.5};
  const Material wall_material{{0.6f, 0.8f, 0.4f}, 1, 0, 0, 0, 1};
  scene.materials = {glass, wall_material};
  // The slab's faces point out of it: the front one up, the back one down.
  const Quad front = quad_at(1, 9), back = quad_at(0.4, 9, false), wall = quad_at(-2, 12);
  scene.objects.push_back({polygon(front), 0});
  scene.objects.push_back({polygon(back), 0});
  scene.objects.push_back({polygon(wall), 1});
  const Rendered r = render(scene);

  // A unit direction crossing a plane z = const out of a medium of index n1
  // into one of n2, eta = n1 / n2: its part along the plane scales by eta
  // (sin t = eta sin i), and it keeps on to the same side.
  const auto cross_plane = [](const V& u, double eta) {
    const double cos2 = 1 - eta * eta * (u.x * u.x + u.y * u.y);
    EXPECT_GT(cos2, 0) << "no total internal reflection in a slab";
    return V{eta * u.x, eta * u.y, std::copysign(std::sqrt(cos2), u.z)};
  };
  // The slab lies beyond the light, seen from the wall.
  const Hidden by_slab = [&](const V& origin, const V& lamp) -> std::optional<bool> {
    const Meet a = meet_quad(origin, lamp - origin, front, 1), b = meet_quad(origin, lamp - origin, back, 1);
    if (a.doubtful || b.doubtful) return std::nullopt;
    return a.t || b.t;
  };
  double most_shift = 0;
  const int called = expect_oracle(r.pixels, scene.camera, [&](int x, int y) -> std::optional<V> {
    const V u = normalize(eye_direction(view, x, y));
    const V from = view.camera.from;
    const Meet in = meet_quad(from, u, front);
    if (in.doubtful) return std::nullopt;
    EXPECT_TRUE(in.t) << "the slab fills the view";
    // Each refracted ray starts just past the face it crossed.
    const V p1 = from + u * *in.t - V{0, 0, r.epsilon};
    const V inside = cross_plane(u, 1 / glass.ior);
    const Meet out = meet_quad(p1, inside, back);
    if (out.doubtful) return std::nullopt;
    EXPECT_TRUE(out.t);
    const V p2 = p1 + inside * *out.t - V{0, 0, r.epsilon};
    const V after = cross_plane(inside, glass.ior);
    const Meet land = meet_quad(p2, after, wall);
    if (land.doubtful) return std::nullopt;
    EXPECT_TRUE(land.t);
    const V p3 = p2 + after * *land.t;
    // How far the slab moved the spot from where the straight ray lands.
    const V straight = from + u * ((wall.v[0].z - from.z) / u.z);
    most_shift = std::max(most_shift, length(p3 - straight));
    const auto lit = direct(p3, wall.normal, -after, wall_material, scene.lights, r.epsilon, by_slab);
    if (!lit) return std::nullopt;
    return lit->sum() * (glass.transmittance * glass.transmittance);
  });
  EXPECT_EQ(called, 24 * 24);
  EXPECT_GT(most_shift, 0.05);
}

}  // namespace
}  // namespace tracer
