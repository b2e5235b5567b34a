// Whitted shading with the NFF model; the rules are stated in render.hpp.
#include <cmath>
#include <limits>

#include "tracer/render.hpp"

namespace tracer {
namespace {

Vec3f reflect(const Vec3f& d, const Vec3f& n) { return d - n * (2.0f * dot(d, n)); }

// Snell's law for unit d and n facing d's origin; nullopt under total internal reflection.
std::optional<Vec3f> refract(const Vec3f& d, const Vec3f& n, float eta) {
  const float cos_i = -dot(d, n);
  const float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
  if (k < 0.0f) return std::nullopt;
  return d * eta + n * (eta * cos_i - std::sqrt(k));
}

struct SurfaceFrame {
  Vec3f geo;      // geometric normal, unit, facing the incoming ray
  Vec3f shading;  // shading normal, unit, on the same side as geo
  bool entering;  // the ray arrives from the side the stored normal points to
};

SurfaceFrame surface_frame(const Hit& hit, const Vec3f& p, const Vec3f& dir,
                           const NormalRecord* normals) {
  const PrimRecord& r = hit.prim;
  Vec3f geo;
  switch (r.kind) {
    case PrimKind::sphere: geo = sphere_normal(r.p0, r.p1.x, p); break;
    case PrimKind::cone: geo = cone_normal({r.p0, r.p1, r.p2.x, r.p2.y}, p); break;
    default: geo = r.p3; break;
  }
  Vec3f shading = geo;
  if (normals) {
    const float w = 1.0f - hit.u - hit.v;
    shading = normalize(normals->n0 * w + normals->n1 * hit.u + normals->n2 * hit.v);
  }
  const bool entering = dot(dir, geo) < 0.0f;
  if (!entering) geo = -geo;
  // An interpolated normal may still face away; it follows the geometric side.
  if (dot(shading, geo) < 0.0f) shading = -shading;
  return {geo, shading, entering};
}

// Where shadow rays of a smooth triangle start: the hit point lifted onto the
// curved surface the vertex normals describe (Hanika's shadow-terminator
// fix), so flat facets do not shadow themselves where the shading is smooth.
// `facing` is the shading normal turned toward the viewer.
Vec3f smooth_shadow_origin(const PrimRecord& r, const NormalRecord& n, const Hit& hit,
                           const Vec3f& p, const Vec3f& facing) {
  const Vec3f v[3] = {r.p0, r.p0 + r.p1, r.p0 + r.p2};
  const float w[3] = {1.0f - hit.u - hit.v, hit.u, hit.v};
  const float side = dot(n.n0 * w[0] + n.n1 * w[1] + n.n2 * w[2], facing) < 0.0f ? -1.0f : 1.0f;
  const Vec3f nv[3] = {n.n0 * side, n.n1 * side, n.n2 * side};
  Vec3f lifted = p;
  for (int i = 0; i < 3; ++i) {
    const float below = dot(p - v[i], nv[i]);
    if (below < 0.0f) lifted -= nv[i] * (w[i] * below);
  }
  return lifted;
}

}  // namespace

Color Tracer::shade(const Ray& ray, int depth, float weight, RayStats& stats) {
  const float t_min = depth == 1 ? camera_.hither() : 0.0f;
  const auto hit = closest_hit(ray, t_min, std::numeric_limits<float>::infinity(), stats);
  if (depth == 1) {
    ++stats.primary;
    stats.primary_hits += hit.has_value();
  }
  if (!hit) return header_.background;
  return shade_hit(ray, *hit, depth, weight, stats);
}

Color Tracer::shade_hit(const Ray& ray, const Hit& hit, int depth, float weight,
                        RayStats& stats) {
  const Vec3f dir = normalize(ray.dir);
  const Vec3f p = ray.origin + ray.dir * hit.t;
  NormalRecord normals;
  const bool smooth = hit.prim.kind == PrimKind::smooth_triangle;
  if (smooth) normals = read<NormalRecord>(Section::normals, hit.prim.aux, stats);
  const SurfaceFrame f = surface_frame(hit, p, dir, smooth ? &normals : nullptr);
  const auto m = read<MaterialRecord>(Section::materials, hit.prim.material, stats);
  const Vec3f light_from =
      smooth ? smooth_shadow_origin(hit.prim, normals, hit, p, f.shading) : p;
  Color c = direct_light(light_from, f.geo, f.shading, -dir, m, stats);

  const bool deeper = depth < options_.max_depth;
  const float eps = header_.epsilon;
  float reflect_weight = m.ks;
  if (deeper && m.transmittance > 0.0f) {
    const float eta = f.entering ? 1.0f / m.ior : m.ior;
    if (const auto t_dir = refract(dir, f.shading, eta)) {
      const float w = weight * m.transmittance;
      if (options_.spd_procedure || w >= options_.min_contribution) {
        ++stats.refracted;
        c += shade({p - f.geo * eps, *t_dir}, depth + 1, w, stats) * m.transmittance;
      }
    } else {
      reflect_weight += m.transmittance;  // total internal reflection
    }
  }
  const bool spd_reflect = options_.spd_procedure && (m.ks > 0.0f || m.transmittance > 0.0f);
  if (deeper && (spd_reflect || (reflect_weight > 0.0f &&
                                 weight * reflect_weight >= options_.min_contribution))) {
    ++stats.reflected;
    // A smooth normal can reflect the ray into the flat facet; mirror it on the facet then.
    Vec3f r_dir = reflect(dir, f.shading);
    if (dot(r_dir, f.geo) <= 0.0f) r_dir = reflect(dir, f.geo);
    const Ray r{p + f.geo * eps, r_dir};
    c += shade(r, depth + 1, weight * reflect_weight, stats) * reflect_weight;
  }
  return c;
}

Color Tracer::direct_light(const Vec3f& p, const Vec3f& n_geo, const Vec3f& n,
                           const Vec3f& view, const MaterialRecord& m, RayStats& stats) {
  Color c{0, 0, 0};
  const Vec3f origin = p + n_geo * header_.epsilon;
  for (const LightRecord& light : header_.lights) {
    Vec3f l = light.position - origin;
    const float dist = length(l);
    l = l * (1.0f / dist);
    const float n_dot_l = dot(n, l);
    // A light behind the surface adds nothing either way; SPD casts no ray
    // to it, VM_pRAY's counts (Table 1) show one cast anyway.
    if (n_dot_l <= 0.0f && !options_.shadow_rays_to_all_lights) continue;
    ++stats.shadow;
    if (occluded({origin, l}, 0.0f, dist, stats) || n_dot_l <= 0.0f) continue;
    c += m.color * light.color * (m.kd * n_dot_l);
    if (m.ks > 0.0f) {
      const float r_dot_v = dot(reflect(-l, n), view);
      if (r_dot_v > 0.0f) c += light.color * (m.ks * std::pow(r_dot_v, m.shine));
    }
  }
  return c;
}

}  // namespace tracer
