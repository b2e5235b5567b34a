// Tracer: paged record reads, BVH and grid traversal, pixels and frames.
// Shading lives in shading.cpp.
#include "tracer/render.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

namespace tracer {

Tracer::Tracer(const DatabaseHeader& header, PageSource& pages, TraceOptions options)
    : header_(header), pages_(pages), options_(options), camera_(header.camera),
      page_stamp_(header.page_count, 0), stack_(3 * std::size_t{header.bvh_depth} + 4) {}

// ---- Paged reads ----

inline const std::byte* Tracer::fetch(PageId id, RayStats& stats) {
  if (last_ptr_ && id == last_page_) return last_ptr_;
  ++stats.page_calls;
  if (page_stamp_[id] != generation_) {
    page_stamp_[id] = generation_;
    ++sample_pages_;
  }
  last_ptr_ = pages_.page(id);
  last_page_ = id;
  return last_ptr_;
}

inline const std::byte* Tracer::locate(Section section, std::uint64_t index, std::size_t size,
                                RayStats& stats) {
  const SectionLayout& s = header_.sections[static_cast<int>(section)];
  const std::uint64_t byte = index * size;
  const std::byte* page = fetch(s.first_page + static_cast<PageId>(byte >> header_.page_shift), stats);
  ++stats.record_reads;
  return page + (byte & (header_.page_size - 1));
}

template <class T>
T Tracer::read(Section section, std::uint64_t index, RayStats& stats) {
  T out;
  std::memcpy(&out, locate(section, index, sizeof(T), stats), sizeof(T));
  return out;
}

// Shading (shading.cpp) reads these records too.
template NormalRecord Tracer::read<NormalRecord>(Section, std::uint64_t, RayStats&);
template MaterialRecord Tracer::read<MaterialRecord>(Section, std::uint64_t, RayStats&);

void Tracer::begin_sample() {
  if (++generation_ == 0) {  // wrapped: forget stale stamps
    std::fill(page_stamp_.begin(), page_stamp_.end(), 0);
    generation_ = 1;
  }
  last_ptr_ = nullptr;  // so every page a sample touches goes through page()
  sample_pages_ = 0;
}

void Tracer::end_sample(RayStats& stats) {
  ++stats.samples;
  stats.distinct_pages += sample_pages_;
}

// ---- Primitive tests and traversal ----

template <bool Any>
bool Tracer::test_prim(std::uint32_t index, const Ray& ray, float t_min, float& t_max, Hit* hit,
                       RayStats& stats) {
  const PrimRecord p = read<PrimRecord>(Section::prims, index, stats);
  ++stats.prim_tests;
  float t = 0, u = 0, v = 0;
  switch (p.kind) {
    case PrimKind::flat_triangle:
    case PrimKind::smooth_triangle: {
      const auto h = intersect_triangle(ray, p.p0, p.p1, p.p2, t_min, t_max);
      if (!h) return false;
      t = h->t, u = h->u, v = h->v;
      break;
    }
    case PrimKind::sphere: {
      const auto h = intersect_sphere(ray, p.p0, p.p1.x, t_min, t_max);
      if (!h) return false;
      t = *h;
      break;
    }
    case PrimKind::cone: {
      const auto h = intersect_cone(ray, {p.p0, p.p1, p.p2.x, p.p2.y}, t_min, t_max);
      if (!h) return false;
      t = *h;
      break;
    }
  }
  t_max = t;
  if (!Any) *hit = Hit{t, u, v, index, p};
  return true;
}

namespace {
// Slab tests of the ray against a node's four boxes, lane by lane (the loop
// vectorises). near/far pick each axis's entry plane by the ray's direction
// sign, so an empty box (lo > hi) is never entered. Returns a hit-lane mask.
// Four floats or lane masks, as GCC/Clang vector types: the four slab tests
// of a node run as one SIMD operation on every target these compilers support.
using Float4 = float __attribute__((vector_size(16)));
using Mask4 = int __attribute__((vector_size(16)));

// `node` points at a BvhNode in a page (or the header); its planes are loaded
// with memcpy. near/far pick each axis's entry plane by the ray's direction
// sign, so an empty box (lo > hi) is never entered. Returns a hit-lane mask.
inline unsigned slab_test4(const std::byte* node, const Ray& ray, const RayInverse& inv,
                           const bool negative[3], float t_min, float t_max, float t_entry[4]) {
  Float4 tn = {t_min, t_min, t_min, t_min}, tf = {t_max, t_max, t_max, t_max};
  for (int a = 0; a < 3; ++a) {
    Float4 near, far;
    const std::size_t lo = offsetof(BvhNode, lo) + a * sizeof(Float4);
    const std::size_t hi = offsetof(BvhNode, hi) + a * sizeof(Float4);
    std::memcpy(&near, node + (negative[a] ? hi : lo), sizeof near);
    std::memcpy(&far, node + (negative[a] ? lo : hi), sizeof far);
    const float o = ray.origin[a], id = inv.inv_dir[a];
    const Float4 n = (near - o) * id, f = (far - o) * id;
    tn = n > tn ? n : tn;  // a NaN plane distance keeps the running bound
    tf = f < tf ? f : tf;
  }
  std::memcpy(t_entry, &tn, sizeof tn);
  const Mask4 hit = tn <= tf;
  return unsigned(hit[0] & 1) | unsigned(hit[1] & 2) | unsigned(hit[2] & 4) | unsigned(hit[3] & 8);
}

// Lane references of a node in a page: child index and primitive count.
inline void lane_refs(const std::byte* node, std::uint32_t child[4], std::uint32_t count[4]) {
  std::memcpy(child, node + offsetof(BvhNode, child), 4 * sizeof(std::uint32_t));
  std::memcpy(count, node + offsetof(BvhNode, count), 4 * sizeof(std::uint32_t));
}
}  // namespace

template <bool Any>
bool Tracer::traverse_bvh(const Ray& ray, float t_min, float& t_max_io, Hit* hit, RayStats& stats) {
  float t_max = t_max_io;  // a local, so stores to the stack or the hit need not reload it
  const RayInverse inv(ray);
  const bool negative[3] = {inv.inv_dir.x < 0, inv.inv_dir.y < 0, inv.inv_dir.z < 0};
  bool found = false;
  std::size_t sp = 0;
  std::uint64_t box_tests = 0;
  // The node being tested, in place: valid until the next page read.
  const std::byte* node = reinterpret_cast<const std::byte*>(&header_.bvh_root);
  for (;;) {
    box_tests += 4;
    float t[4];
    unsigned mask = slab_test4(node, ray, inv, negative, t_min, t_max, t);
    std::uint32_t child[4], count[4];
    lane_refs(node, child, count);
    // Stack the lanes met, farthest first, so the nearest is popped next
    // (any-hit rays need no order).
    const std::size_t base = sp;
    for (; mask; mask &= mask - 1) {
      const int lane = std::countr_zero(mask);
      std::size_t k = sp++;
      if constexpr (!Any)
        for (; k > base && stack_[k - 1].t < t[lane]; --k) stack_[k] = stack_[k - 1];
      stack_[k] = {child[lane], count[lane], t[lane]};
    }
    // Run leaves and pop until the next inner node.
    for (;;) {
      StackEntry e;
      do {
        if (sp == 0) {
          stats.box_tests += box_tests;
          t_max_io = t_max;
          return found;
        }
        e = stack_[--sp];
      } while (e.t > t_max);  // beyond the closest hit so far
      if (e.count == 0) {
        node = locate(Section::bvh_nodes, e.child, sizeof(BvhNode), stats);
        break;
      }
      for (std::uint32_t k = 0; k < e.count; ++k) {
        if (test_prim<Any>(e.child + k, ray, t_min, t_max, hit, stats)) {
          if (Any) {
            stats.box_tests += box_tests;
            t_max_io = t_max;
            return true;
          }
          found = true;
        }
      }
    }
  }
}

namespace {
// 3-D DDA state (Amanatides & Woo) for the uniform grid.
struct GridWalk {
  int cell[3], step[3];
  float t_next[3], t_delta[3];
};

GridWalk start_walk(const DatabaseHeader& h, const Ray& ray, const RayInverse& inv, float t) {
  GridWalk w{};
  const Vec3f p = ray.origin + ray.dir * t;
  for (int a = 0; a < 3; ++a) {
    const float size = (h.bounds.hi[a] - h.bounds.lo[a]) / h.grid_dims[a];
    const float rel = size > 0 ? (p[a] - h.bounds.lo[a]) / size : 0.0f;
    w.cell[a] = std::clamp(static_cast<int>(rel), 0, h.grid_dims[a] - 1);
    const float inf = std::numeric_limits<float>::infinity();
    if (ray.dir[a] > 0) {
      w.step[a] = 1;
      w.t_next[a] = (h.bounds.lo[a] + (w.cell[a] + 1) * size - ray.origin[a]) * inv.inv_dir[a];
      w.t_delta[a] = size * inv.inv_dir[a];
    } else if (ray.dir[a] < 0) {
      w.step[a] = -1;
      w.t_next[a] = (h.bounds.lo[a] + w.cell[a] * size - ray.origin[a]) * inv.inv_dir[a];
      w.t_delta[a] = -size * inv.inv_dir[a];
    } else {
      w.step[a] = 0;
      w.t_next[a] = inf;
      w.t_delta[a] = inf;
    }
  }
  return w;
}
}  // namespace

template <bool Any>
bool Tracer::traverse_grid(const Ray& ray, float t_min, float& t_max, Hit* hit, RayStats& stats) {
  const RayInverse inv(ray);
  const auto entry = intersect_box(ray, inv, header_.bounds, t_min, t_max);
  if (!entry) return false;
  GridWalk w = start_walk(header_, ray, inv, *entry);
  const int* dims = header_.grid_dims;
  for (;;) {
    ++stats.box_tests;
    const std::uint64_t index =
        w.cell[0] + std::uint64_t(dims[0]) * (w.cell[1] + std::uint64_t(dims[1]) * w.cell[2]);
    const GridCell cell = read<GridCell>(Section::grid_cells, index, stats);
    const int axis = w.t_next[0] < w.t_next[1] ? (w.t_next[0] < w.t_next[2] ? 0 : 2)
                                               : (w.t_next[1] < w.t_next[2] ? 1 : 2);
    // Only hits inside this cell count: a later cell may hold a nearer one.
    float limit = std::min(t_max, w.t_next[axis]);
    bool found = false;
    for (std::uint32_t k = 0; k < cell.count; ++k) {
      const auto prim = read<std::uint32_t>(Section::grid_lists, cell.first + std::uint64_t{k}, stats);
      if (test_prim<Any>(prim, ray, t_min, limit, hit, stats)) {
        if (Any) return true;
        found = true;
      }
    }
    if (found) {
      t_max = limit;
      return true;
    }
    if (w.t_next[axis] > t_max) return false;
    w.cell[axis] += w.step[axis];
    if (w.cell[axis] < 0 || w.cell[axis] >= dims[axis]) return false;
    w.t_next[axis] += w.t_delta[axis];
  }
}

std::optional<Hit> Tracer::closest_hit(const Ray& ray, float t_min, float t_max, RayStats& stats) {
  if (header_.primitive_count == 0) return std::nullopt;
  Hit hit;
  const bool found = header_.accel == Accel::bvh
                         ? traverse_bvh<false>(ray, t_min, t_max, &hit, stats)
                         : traverse_grid<false>(ray, t_min, t_max, &hit, stats);
  return found ? std::optional<Hit>(hit) : std::nullopt;
}

bool Tracer::occluded(const Ray& ray, float t_min, float t_max, RayStats& stats) {
  if (header_.primitive_count == 0) return false;
  return header_.accel == Accel::bvh ? traverse_bvh<true>(ray, t_min, t_max, nullptr, stats)
                                     : traverse_grid<true>(ray, t_min, t_max, nullptr, stats);
}

// ---- Pixels and frames ----

Color Tracer::trace_eye(const Ray& ray, RayStats& stats) {
  begin_sample();
  const Color c = shade(ray, 1, 1.0f, stats);
  end_sample(stats);
  return c;
}

Color Tracer::trace_pixel(int x, int y, RayStats& stats) {
  return trace_eye(camera_.ray_through(x, y), stats);
}

Color Tracer::trace_sample(int sx, int sy, RayStats& stats) {
  return trace_eye(camera_.ray_through(sx - 0.5, sy - 0.5), stats);
}

Color Tracer::average_corners(const Color& c00, const Color& c10, const Color& c01,
                              const Color& c11) {
  return (c00 + c10 + c01 + c11) * 0.25f;
}

std::vector<Color> render_frame(const DatabaseHeader& header, PageSource& pages,
                                const TraceOptions& options, RayStats& stats,
                                const std::function<void(int)>& progress) {
  const int w = header.camera.width, h = header.camera.height;
  Tracer tracer(header, pages, options);
  std::vector<Color> out(std::size_t(w) * h);
  if (!options.spd_procedure) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) out[std::size_t(y) * w + x] = tracer.trace_pixel(x, y, stats);
      if (progress) progress(y + 1);
    }
    return out;
  }
  // SPD: keep two rows of corner samples.
  std::vector<Color> above(w + 1), below(w + 1);
  for (int sx = 0; sx <= w; ++sx) above[sx] = tracer.trace_sample(sx, 0, stats);
  for (int y = 0; y < h; ++y) {
    for (int sx = 0; sx <= w; ++sx) below[sx] = tracer.trace_sample(sx, y + 1, stats);
    for (int x = 0; x < w; ++x)
      out[std::size_t(y) * w + x] =
          Tracer::average_corners(above[x], above[x + 1], below[x], below[x + 1]);
    std::swap(above, below);
    if (progress) progress(y + 1);
  }
  return out;
}

}  // namespace tracer
