// Tracer: paged record reads, BVH and grid traversal, pixels and frames.
// Shading lives in shading.cpp.
#include "tracer/render.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <memory>

#include "tracer/grid.hpp"
#include "tracer/huge_pages.hpp"
#include "tracer/parallel.hpp"

namespace tracer {

Tracer::Tracer(const DatabaseHeader& header, PageSource& pages, TraceOptions options)
    : header_(header),
      pages_(pages),
      options_(options),
      camera_(header.camera),
      page_stamp_(header.page_count, 0),
      stack_(3 * std::size_t{header.bvh_depth} + 4),
      mailbox_(header.accel == Accel::grid ? kMailboxSlots : 0, 0) {}

// ---- Paged reads ----

inline const std::byte* Tracer::fetch(PageId id, RayStats& stats) {
  if (id == last_page_) return last_ptr_;
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
  last_page_ = kNoPage;  // so every page a sample touches goes through page()
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
  return test_record<Any>(read<PrimRecord>(Section::prims, index, stats), index, ray, t_min, t_max, hit, stats);
}

template <bool Any>
bool Tracer::test_record(const PrimRecord& p, std::uint32_t index, const Ray& ray, float t_min, float& t_max, Hit* hit,
                         RayStats& stats) {
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
// Four floats or lane masks, as GCC/Clang vector types: the four slab tests
// of a node run as one SIMD operation on every target these compilers support.
using Float4 = float __attribute__((vector_size(16)));
using Mask4 = int __attribute__((vector_size(16)));

// Bit i set when lane i of a comparison result is true (all ones).
inline unsigned lane_bits(Mask4 m) {
#ifdef __SSE__
  return static_cast<unsigned>(__builtin_ia32_movmskps(reinterpret_cast<Float4>(m)));
#else
  return unsigned(m[0] & 1) | unsigned(m[1] & 2) | unsigned(m[2] & 4) | unsigned(m[3] & 8);
#endif
}

inline Float4 splat(float x) { return Float4{x, x, x, x}; }
inline float load_float(const std::byte* p) {
  float f;
  std::memcpy(&f, p, sizeof f);
  return f;
}

// A ray prepared once for the slab tests of four-wide nodes: its origin and
// reciprocal direction in every lane, and the byte offsets in a BvhNode of
// each axis's entry (near) and exit (far) planes.
struct SlabRay {
  Float4 origin[3], inv_dir[3];
  std::size_t near[3], far[3];
  explicit SlabRay(const Ray& ray) {
    const RayInverse inv(ray);
    for (int a = 0; a < 3; ++a) {
      origin[a] = splat(ray.origin[a]);
      inv_dir[a] = splat(inv.inv_dir[a]);
      const std::size_t lo = offsetof(BvhNode, lo) + a * sizeof(Float4);
      const std::size_t hi = offsetof(BvhNode, hi) + a * sizeof(Float4);
      near[a] = inv.inv_dir[a] < 0 ? hi : lo;
      far[a] = inv.inv_dir[a] < 0 ? lo : hi;
    }
  }
};

// Slab tests of the ray against a node's four boxes at once. `node` points at
// a BvhNode in a page (or the header); its planes are loaded with memcpy.
// Entering by the near planes means an empty box (lo > hi) is never entered.
// Returns a hit-lane mask.
inline unsigned slab_test4(const std::byte* node, const SlabRay& ray, float t_min, float t_max,
                           float t_entry[4]) {
  Float4 tn = splat(t_min), tf = splat(t_max);
  for (int a = 0; a < 3; ++a) {
    Float4 near, far;
    std::memcpy(&near, node + ray.near[a], sizeof near);
    std::memcpy(&far, node + ray.far[a], sizeof far);
    const Float4 n = (near - ray.origin[a]) * ray.inv_dir[a], f = (far - ray.origin[a]) * ray.inv_dir[a];
    tn = n > tn ? n : tn;  // a NaN plane distance keeps the running bound
    tf = f < tf ? f : tf;
  }
  std::memcpy(t_entry, &tn, sizeof tn);
  return lane_bits(tn <= tf);
}

// Four rows of four floats transposed into four columns (pure data moves).
inline void transpose4(const Float4 row[4], Float4 col[4]) {
  const Float4 xy01 = __builtin_shufflevector(row[0], row[1], 0, 4, 1, 5);
  const Float4 xy23 = __builtin_shufflevector(row[2], row[3], 0, 4, 1, 5);
  const Float4 zw01 = __builtin_shufflevector(row[0], row[1], 2, 6, 3, 7);
  const Float4 zw23 = __builtin_shufflevector(row[2], row[3], 2, 6, 3, 7);
  col[0] = __builtin_shufflevector(xy01, xy23, 0, 1, 4, 5);
  col[1] = __builtin_shufflevector(xy01, xy23, 2, 3, 6, 7);
  col[2] = __builtin_shufflevector(zw01, zw23, 0, 1, 4, 5);
  col[3] = __builtin_shufflevector(zw01, zw23, 2, 3, 6, 7);
}

// Moeller-Trumbore on four triangles side by side, each lane the same float
// operations in the same order as intersect_triangle, so t, u and v are
// bit-identical to the scalar test (no FMA on baseline x86-64, and GCC does not
// reassociate without -ffast-math). lane[k] points at the triangle PrimRecord
// lane k tests, one of `count` (1..4) packed in a page; lanes past `count`
// repeat the last one. Returns the mask of lanes hit in (t_min, t_max).
inline unsigned triangles4(const std::byte* const lane[4], std::uint32_t count, const Ray& ray,
                           float t_min, float t_max, Float4& t, Float4& u, Float4& v) {
  // c[j]: float j of v0, e1, e2 in each lane. Floats 0..7 of each record come
  // in two 16-byte rows per lane and are transposed; float 8 is gathered.
  Float4 rows[2][4], c[9];
  constexpr std::size_t p0 = offsetof(PrimRecord, p0);
  for (int k = 0; k < 4; ++k) {
    std::memcpy(&rows[0][k], lane[k] + p0, sizeof(Float4));
    std::memcpy(&rows[1][k], lane[k] + p0 + sizeof(Float4), sizeof(Float4));
  }
  transpose4(rows[0], c);
  transpose4(rows[1], c + 4);
  c[8] = Float4{load_float(lane[0] + p0 + 32), load_float(lane[1] + p0 + 32),
                load_float(lane[2] + p0 + 32), load_float(lane[3] + p0 + 32)};
  const Float4 dx = splat(ray.dir.x), dy = splat(ray.dir.y), dz = splat(ray.dir.z);
  const Float4 px = dy * c[8] - dz * c[7], py = dz * c[6] - dx * c[8], pz = dx * c[7] - dy * c[6];
  const Float4 det = c[3] * px + c[4] * py + c[5] * pz;
  const Float4 inv_det = 1.0f / det;
  const Float4 sx = ray.origin.x - c[0], sy = ray.origin.y - c[1], sz = ray.origin.z - c[2];
  u = (sx * px + sy * py + sz * pz) * inv_det;
  const Float4 qx = sy * c[5] - sz * c[4], qy = sz * c[3] - sx * c[5], qz = sx * c[4] - sy * c[3];
  v = (dx * qx + dy * qy + dz * qz) * inv_det;
  t = (c[6] * qx + c[7] * qy + c[8] * qz) * inv_det;
  // The scalar test's rejections, negated as written there (a NaN u or v passes them).
  const Mask4 miss = (det == 0.0f) | (u < 0.0f) | (u > 1.0f) | (v < 0.0f) | (u + v > 1.0f);
  return lane_bits(~miss & (t > t_min) & (t < t_max)) & ((1u << count) - 1);
}

}  // namespace

// A BVH leaf: primitives first..first+count-1 in order, as test_prim one by
// one would, in runs of at most four records that lie in one page. A run of
// triangles goes through the four-wide test with the loop's outcome: the
// nearest hit, the first of equal ones (the loop's strict t < t_max), or for
// any-hit rays the first hit in order, with the statistics of the records the
// loop would have read. Runs follow each other as the loop's records do, the
// next one seeing the t_max the previous one left.
template <bool Any>
[[gnu::always_inline]] inline bool Tracer::test_leaf(std::uint32_t first, std::uint32_t count, const Ray& ray,
                                                     float t_min, float& t_max, Hit* hit, RayStats& stats) {
  const std::uint32_t page_records = header_.page_size / sizeof(PrimRecord);  // a power of two >= 4
  bool found = false;
  for (std::uint32_t k = first, end = first + count; k < end;) {
    const std::uint32_t run = std::min({end - k, 4u, page_records - (k & (page_records - 1))});
    if (test_run<Any>(k, run, ray, t_min, t_max, hit, stats)) {
      if (Any) return true;
      found = true;
    }
    k += run;
  }
  return found;
}

template <bool Any>
[[gnu::always_inline]] inline bool Tracer::test_run(std::uint32_t first, std::uint32_t count, const Ray& ray,
                                                    float t_min, float& t_max, Hit* hit, RayStats& stats) {
  const std::uint64_t first_byte = std::uint64_t{first} * sizeof(PrimRecord);
  // Records are counted below, as many as the loop would read.
  const PageId page = header_.section(Section::prims).first_page +
                      static_cast<PageId>(first_byte >> header_.page_shift);
  const std::byte* recs = fetch(page, stats) + (first_byte & (header_.page_size - 1));
  // The record each lane of the four-wide test reads; lanes past `count`
  // repeat the last one. The kinds of triangles are 0 and 1, so the bitwise
  // or of the four kinds is at most 1 exactly when all are triangles.
  static_assert(std::uint32_t(PrimKind::flat_triangle) == 0 && std::uint32_t(PrimKind::smooth_triangle) == 1);
  const std::byte* lane[4];
  std::uint32_t kinds = 0;
  for (std::uint32_t k = 0; k < 4; ++k) {
    lane[k] = recs + std::min(k, count - 1) * sizeof(PrimRecord);
    std::uint32_t kind;
    std::memcpy(&kind, lane[k] + offsetof(PrimRecord, kind), sizeof kind);
    kinds |= kind;
  }
  if (kinds > 1) {
    bool found = false;
    for (std::uint32_t k = 0; k < count; ++k) {
      if (!test_prim<Any>(first + k, ray, t_min, t_max, hit, stats)) continue;
      if (Any) return true;
      found = true;
    }
    return found;
  }
  Float4 t, u, v;
  const unsigned mask = triangles4(lane, count, ray, t_min, t_max, t, u, v);
  if (Any) {
    const std::uint32_t tested = mask ? std::countr_zero(mask) + 1 : count;
    stats.prim_tests += tested;
    stats.record_reads += tested;
    if (mask) t_max = t[std::countr_zero(mask)];
    return mask != 0;
  }
  stats.prim_tests += count;
  stats.record_reads += count;
  if (!mask) return false;
  int best = std::countr_zero(mask);
  for (unsigned m = mask & (mask - 1); m; m &= m - 1) {
    const int lane = std::countr_zero(m);
    if (t[lane] < t[best]) best = lane;
  }
  t_max = t[best];
  hit->t = t[best], hit->u = u[best], hit->v = v[best];
  hit->prim_index = first + best;
  std::memcpy(&hit->prim, recs + best * sizeof(PrimRecord), sizeof(PrimRecord));
  return true;
}

template <bool Any>
bool Tracer::traverse_bvh(const Ray& ray, float t_min, float& t_max_io, Hit* hit, RayStats& stats) {
  float t_max = t_max_io;  // a local, so stores to the stack or the hit need not reload it
  const SlabRay slab_ray(ray);
  bool found = false;
  std::size_t sp = 0;
  StackEntry* const stack = stack_.data();  // a local: stores through it cannot move it
  // Where node records lie, in locals: stores made while traversing cannot change them.
  const PageId node_pages = header_.section(Section::bvh_nodes).first_page;
  const std::uint32_t page_shift = header_.page_shift;
  const std::uint64_t offset_mask = header_.page_size - 1;
  std::uint64_t box_tests = 0, node_reads = 0;
  const auto node_at = [&](std::uint32_t index) {
    const std::uint64_t byte = std::uint64_t{index} * sizeof(BvhNode);
    ++node_reads;
    return fetch(node_pages + static_cast<PageId>(byte >> page_shift), stats) + (byte & offset_mask);
  };
  // Lane `lane` of a node in a page: its child index and primitive count, met at t.
  const auto lane_entry = [](const std::byte* at, int lane, float t) {
    StackEntry e{0, 0, t};
    std::memcpy(&e.child, at + offsetof(BvhNode, child) + lane * sizeof(std::uint32_t), sizeof e.child);
    std::memcpy(&e.count, at + offsetof(BvhNode, count) + lane * sizeof(std::uint32_t), sizeof e.count);
    return e;
  };
  const auto finish = [&] {
    stats.box_tests += box_tests;
    stats.record_reads += node_reads;
    t_max_io = t_max;
  };
  // The node being tested, in place: valid until the next page read.
  const std::byte* node = reinterpret_cast<const std::byte*>(&header_.bvh_root);
  for (;;) {
    box_tests += 4;
    float t[4];
    unsigned mask = slab_test4(node, slab_ray, t_min, t_max, t);
    // One inner lane met: go down to it without a stack round trip.
    if (mask && !(mask & (mask - 1))) {
      const int lane = std::countr_zero(mask);
      const StackEntry only = lane_entry(node, lane, t[lane]);
      if (only.count == 0) {
        node = node_at(only.child);
        continue;
      }
    }
    // Stack the lanes met, farthest first, so the nearest is popped next
    // (any-hit rays need no order). An inner lane's node, when it lies in the
    // page at hand (most do: treelets), is prefetched, so that a big scene's
    // nodes come from memory while the nearer lanes are traversed.
    // An entry's child and count are stored as one 8-byte word, so that an
    // entry moved up by the insertion loop just after being written is read
    // back as it was stored (two 4-byte stores read as one 8-byte load would
    // stall the load until the stores retire).
    const std::size_t base = sp;
    for (; mask; mask &= mask - 1) {
      const int lane = std::countr_zero(mask);
      const StackEntry e = lane_entry(node, lane, t[lane]);
      const std::uint64_t word = std::uint64_t{e.child} | std::uint64_t{e.count} << 32;
      if (e.count == 0) {
        const std::uint64_t byte = std::uint64_t{e.child} * sizeof(BvhNode);
        if (node_pages + static_cast<PageId>(byte >> page_shift) == last_page_)
          __builtin_prefetch(last_ptr_ + (byte & offset_mask));
      }
      std::size_t k = sp++;
      if constexpr (!Any)
        for (; k > base && stack[k - 1].t < e.t; --k) stack[k] = stack[k - 1];
      static_assert(offsetof(StackEntry, child) == 0 && offsetof(StackEntry, count) == 4 &&
                    std::endian::native == std::endian::little);
      std::memcpy(&stack[k], &word, sizeof word);
      stack[k].t = e.t;
    }
    // Run leaves and pop until the next inner node.
    for (;;) {
      StackEntry e;
      do {
        if (sp == 0) {
          finish();
          return found;
        }
        e = stack[--sp];
      } while (!Any && e.t > t_max);  // beyond the closest hit so far
      if (e.count == 0) {
        node = node_at(e.child);
        break;
      }
      if (test_leaf<Any>(e.child, e.count, ray, t_min, t_max, hit, stats)) {
        if (Any) {
          finish();
          return true;
        }
        found = true;
      }
    }
  }
}

namespace {
// 3-D DDA state (Amanatides & Woo) for the uniform grid: the cell, its index
// in the cell section, and per axis the step, the index stride of one step
// (signed), the distance at which the ray leaves the cell and the distance
// between two boundaries. All divisions happen here, none in the walk.
struct GridWalk {
  int cell[3], step[3];
  std::int64_t index, stride[3];
  float t_next[3], t_delta[3];
};

// The walk of a grid of `dims` cells over `box` from the point at distance t.
[[gnu::always_inline]] inline GridWalk start_walk(const Box3f& box, const int dims[3], const Ray& ray,
                                                  const RayInverse& inv, float t) {
  GridWalk w{};
  const Vec3f p = ray.origin + ray.dir * t;
  const std::int64_t strides[3] = {1, dims[0], std::int64_t{dims[0]} * dims[1]};
  w.index = 0;
  for (int a = 0; a < 3; ++a) {
    const float size = (box.hi[a] - box.lo[a]) / dims[a];
    const float rel = size > 0 ? (p[a] - box.lo[a]) / size : 0.0f;
    w.cell[a] = clamped_int(rel, 0, dims[a] - 1);
    w.index += w.cell[a] * strides[a];
    const float inf = std::numeric_limits<float>::infinity();
    if (ray.dir[a] > 0) {
      w.step[a] = 1;
      w.t_next[a] = (box.lo[a] + (w.cell[a] + 1) * size - ray.origin[a]) * inv.inv_dir[a];
      w.t_delta[a] = size * inv.inv_dir[a];
    } else if (ray.dir[a] < 0) {
      w.step[a] = -1;
      w.t_next[a] = (box.lo[a] + w.cell[a] * size - ray.origin[a]) * inv.inv_dir[a];
      w.t_delta[a] = -size * inv.inv_dir[a];
    } else {
      w.step[a] = 0;
      w.t_next[a] = inf;
      w.t_delta[a] = inf;
    }
    w.stride[a] = w.step[a] * strides[a];
  }
  return w;
}

// A primitive record copied in the pieces triangles4 reads back (its first
// two rows, 16 bytes each from p0, and the float after them), so that each
// of those loads, and a copy back made the same way, finds one store to
// forward from; a copy in four aligned rows would make two of them wait for
// the stores to reach the cache.
[[gnu::always_inline]] inline void copy_record(void* to, const std::byte* from) {
  constexpr std::size_t p0 = offsetof(PrimRecord, p0);
  auto* out = static_cast<std::byte*>(to);
  std::memcpy(out, from, p0);
  std::memcpy(out + p0, from + p0, 16);
  std::memcpy(out + p0 + 16, from + p0 + 16, 16);
  std::memcpy(out + p0 + 32, from + p0 + 32, sizeof(PrimRecord) - p0 - 32);
}
}  // namespace

inline std::uint64_t Tracer::next_ray_tag() {
  if (++ray_id_ == 0) {  // wrapped: no slot may still hold a tag of this id
    std::fill(mailbox_.begin(), mailbox_.end(), 0);
    ray_id_ = 1;
  }
  return std::uint64_t{ray_id_} << 32;
}

// A cell's primitives, read from the cell-list section in runs that lie in
// one page (copied out before the primitives' pages are read), each skipped
// if the mailbox says this ray tested it already, triangles tested four at a
// time from records copied out of their pages. The order of the tests is the
// list's, so among hits at equal distance the first listed wins, as when
// testing one by one.
template <bool Any>
bool Tracer::test_cell(const GridCell& cell, std::uint64_t ray_tag, const Ray& ray, float t_min, float& t_max, Hit* hit,
                       RayStats& stats) {
  const SectionLayout& lists = header_.section(Section::grid_lists);
  const SectionLayout& prims = header_.section(Section::prims);
  const std::uint32_t page_shift = header_.page_shift;
  const std::uint64_t offset_mask = header_.page_size - 1;
  constexpr std::size_t kRun = 64;
  std::uint32_t ids[kRun];
  // Up to four triangles copied out of their pages, 16-byte aligned for the
  // four-wide test's row loads.
  alignas(16) std::byte batch[4][sizeof(PrimRecord)];
  std::uint32_t batch_ids[4];
  std::uint32_t in_batch = 0;
  bool found = false;
  const auto flush = [&]() -> bool {
    if (in_batch == 0) return false;
    const std::byte* lane[4];
    for (std::uint32_t k = 0; k < 4; ++k) lane[k] = batch[std::min(k, in_batch - 1)];
    Float4 t, u, v;
    const unsigned mask = triangles4(lane, in_batch, ray, t_min, t_max, t, u, v);
    const std::uint32_t count = in_batch;
    in_batch = 0;
    if (Any) {
      stats.prim_tests += mask ? std::countr_zero(mask) + 1 : count;
      return mask != 0;
    }
    stats.prim_tests += count;
    if (!mask) return false;
    int best = std::countr_zero(mask);
    for (unsigned m = mask & (mask - 1); m; m &= m - 1) {
      const int l = std::countr_zero(m);
      if (t[l] < t[best]) best = l;
    }
    t_max = t[best];
    hit->t = t[best], hit->u = u[best], hit->v = v[best];
    hit->prim_index = batch_ids[best];
    copy_record(&hit->prim, batch[best]);
    return true;
  };
  for (std::uint32_t k = 0; k < cell.count;) {
    const std::uint64_t byte = (std::uint64_t{cell.first} + k) * sizeof(std::uint32_t);
    const std::uint64_t offset = byte & offset_mask;
    const std::uint64_t in_page = (header_.page_size - offset) / sizeof(std::uint32_t);  // ids left in the page
    const std::size_t run = std::min<std::uint64_t>({cell.count - k, kRun, in_page});
    const std::byte* from = fetch(lists.first_page + static_cast<PageId>(byte >> page_shift), stats) + offset;
    // A short run is copied as sixteen ids when the page holds them, a copy of
    // fixed size that needs no call; the ids past the run are not used.
    if (run <= 16 && in_page >= 16)
      std::memcpy(ids, from, 16 * sizeof(std::uint32_t));
    else
      std::memcpy(ids, from, run * sizeof(std::uint32_t));
    stats.record_reads += run;
    k += static_cast<std::uint32_t>(run);
    for (std::size_t i = 0; i < run; ++i) {
      const std::uint32_t id = ids[i];
      std::uint64_t& slot = mailbox_[id & (kMailboxSlots - 1)];
      if (slot == (ray_tag | id)) continue;  // tested by this ray in an earlier cell
      slot = ray_tag | id;
      const std::uint64_t at = std::uint64_t{id} * sizeof(PrimRecord);
      const std::byte* rec =
          fetch(prims.first_page + static_cast<PageId>(at >> page_shift), stats) + (at & offset_mask);
      ++stats.record_reads;
      std::uint32_t kind;
      std::memcpy(&kind, rec + offsetof(PrimRecord, kind), sizeof kind);
      if (kind <= std::uint32_t(PrimKind::smooth_triangle)) {
        copy_record(batch[in_batch], rec);
        batch_ids[in_batch++] = id;
        if (in_batch < 4) continue;
        if (flush()) {
          if (Any) return true;
          found = true;
        }
        continue;
      }
      PrimRecord p;
      std::memcpy(&p, rec, sizeof p);
      if (flush()) {  // the triangles listed before it go first
        if (Any) return true;
        found = true;
      }
      if (test_record<Any>(p, id, ray, t_min, t_max, hit, stats)) {
        if (Any) return true;
        found = true;
      }
    }
  }
  if (flush()) {
    if (Any) return true;
    found = true;
  }
  return found;
}

namespace {
// An empty cell at least this far from the nearest occupied one is jumped
// over with the cube of empty cells around it; nearer, the walk steps (a
// jump costs a division, a step reads one cell).
constexpr std::uint32_t kGridJumpDistance = 2;

// Moves the walk from an empty cell `distance` cells from the nearest
// occupied one (records.hpp) to the first cell the ray meets beyond the cube
// of cells within distance - 1 on every axis, all empty, clipped to the grid:
// each axis steps over the cell boundaries the ray crosses before it leaves
// the cube, as the walk would one by one. t_enter becomes the distance at
// which the ray leaves the cube. False when the ray leaves the grid there, or
// t_max lies before: no later cell can hold a nearer hit.
bool jump_empty(GridWalk& w, const int dims[3], std::uint32_t distance, float t_max, float& t_enter) {
  const int r = static_cast<int>(std::min<std::uint32_t>(distance - 1, 1u << 20));
  int reach[3] = {0, 0, 0};
  float t_exit = std::numeric_limits<float>::infinity();
  int exit_axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (w.step[a] == 0) continue;
    reach[a] = std::min(r, w.step[a] > 0 ? dims[a] - 1 - w.cell[a] : w.cell[a]);
    const float t = w.t_next[a] + static_cast<float>(reach[a]) * w.t_delta[a];
    if (t < t_exit) t_exit = t, exit_axis = a;
  }
  if (exit_axis < 0 || t_exit >= t_max) return false;
  for (int a = 0; a < 3; ++a) {
    if (w.step[a] == 0) continue;
    int k = reach[a] + 1;  // the exit axis also crosses the cube's face
    if (a != exit_axis) {
      const float q = (t_exit - w.t_next[a]) / w.t_delta[a];  // NaN for a flat axis: no step
      k = q > 0 ? (q < static_cast<float>(reach[a]) ? static_cast<int>(q) : reach[a]) : 0;
      while (k < reach[a] && w.t_next[a] + static_cast<float>(k) * w.t_delta[a] < t_exit) ++k;
    }
    w.cell[a] += w.step[a] * k;
    w.index += w.stride[a] * k;
    w.t_next[a] += static_cast<float>(k) * w.t_delta[a];
  }
  if (w.cell[exit_axis] < 0 || w.cell[exit_axis] >= dims[exit_axis]) return false;
  t_enter = t_exit;
  return true;
}
}  // namespace

// The walk keeps the nearest hit of the cells met so far and stops at the
// first cell the ray leaves beyond it: a primitive spans several cells, so a
// hit found in one cell may lie in a later one, where a primitive met there
// could be nearer; with the mailbox each primitive is tested once a ray. A
// top cell holding a subgrid is walked the same way from where the ray
// enters it (Top = false: a subgrid holds no subgrid). Inlined, as the
// walk's start is, so that entering a subgrid costs no call.
template <bool Any, bool Top>
[[gnu::always_inline]] inline bool Tracer::walk_grid(const Box3f& box, const int dims[3], std::uint64_t base,
                                                   float t_enter, const Ray& ray, const RayInverse& inv,
                                                   std::uint64_t ray_tag, float t_min, float& t_max, Hit* hit,
                                                   RayStats& stats) {
  GridWalk w = start_walk(box, dims, ray, inv, t_enter);
  bool found = false;
  for (;;) {
    ++stats.box_tests;
    const GridCell cell = read<GridCell>(Section::grid_cells, base + static_cast<std::uint64_t>(w.index), stats);
    // An empty cell far from any other: jump over the empty cells around it.
    if (cell.count == 0 && (cell.first & 0xffff) > kGridJumpDistance) {
      if (!jump_empty(w, dims, cell.first & 0xffff, t_max, t_enter)) return found;
      continue;
    }
    if constexpr (Top) {
      if (cell.count & kGridSubgridFlag) {
        int sub[3];
        decode_subgrid(cell.count, sub);
        if (walk_grid<Any, false>(grid_cell_box(box, dims, w.cell), sub, cell.first, t_enter, ray, inv, ray_tag, t_min,
                                  t_max, hit, stats)) {
          found = true;
          if (Any) return true;
        }
      } else if (cell.count != 0 && test_cell<Any>(cell, ray_tag, ray, t_min, t_max, hit, stats)) {
        found = true;
        if (Any) return true;
      }
    } else if (cell.count != 0 && test_cell<Any>(cell, ray_tag, ray, t_min, t_max, hit, stats)) {
      found = true;
      if (Any) return true;
    }
    // The next cell, or from an empty one the next few, which are empty too.
    for (std::uint32_t steps = cell.count == 0 ? cell.first >> 16 : 1; steps > 0; --steps) {
      const int axis =
          w.t_next[0] < w.t_next[1] ? (w.t_next[0] < w.t_next[2] ? 0 : 2) : (w.t_next[1] < w.t_next[2] ? 1 : 2);
      // Every later cell begins at t_next[axis] or beyond, and a hit must be
      // nearer than t_max.
      if (w.t_next[axis] >= t_max) return found;
      w.cell[axis] += w.step[axis];
      if (w.cell[axis] < 0 || w.cell[axis] >= dims[axis]) return found;
      w.index += w.stride[axis];
      t_enter = w.t_next[axis];
      w.t_next[axis] += w.t_delta[axis];
    }
  }
}

template <bool Any>
bool Tracer::traverse_grid(const Ray& ray, float t_min, float& t_max_io, Hit* hit, RayStats& stats) {
  const RayInverse inv(ray);
  const auto entry = intersect_box(ray, inv, header_.bounds, t_min, t_max_io);
  if (!entry) return false;
  float t_max = t_max_io;
  const bool found = walk_grid<Any, true>(header_.bounds, header_.grid_dims, 0, *entry, ray, inv, next_ray_tag(), t_min,
                                          t_max, hit, stats);
  if (found) t_max_io = t_max;
  return found;
}

std::optional<Hit> Tracer::closest_hit(const Ray& ray, float t_min, float t_max, RayStats& stats) {
  if (ray_hook_) ray_hook_(ray_hook_context_);
  if (header_.primitive_count == 0) return std::nullopt;
  Hit hit;
  const bool found = header_.accel == Accel::bvh
                         ? traverse_bvh<false>(ray, t_min, t_max, &hit, stats)
                         : traverse_grid<false>(ray, t_min, t_max, &hit, stats);
  return found ? std::optional<Hit>(hit) : std::nullopt;
}

bool Tracer::occluded(const Ray& ray, float t_min, float t_max, RayStats& stats) {
  if (ray_hook_) ray_hook_(ray_hook_context_);
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

namespace {
// A frame's pixels, advised for huge pages before they are written: a big
// frame is fresh memory written once, pixel by pixel.
std::vector<Color> frame_buffer(int w, int h) {
  std::vector<Color> out;
  out.reserve(std::size_t(w) * h);
  advise_huge_pages(out.data(), out.capacity() * sizeof(Color));
  out.resize(std::size_t(w) * h);
  return out;
}
}  // namespace

std::vector<Color> render_frame(const DatabaseHeader& header, PageSource& pages,
                                const TraceOptions& options, RayStats& stats,
                                const std::function<void(int)>& progress) {
  const int w = header.camera.width, h = header.camera.height;
  Tracer tracer(header, pages, options);
  std::vector<Color> out = frame_buffer(w, h);
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

namespace {

// One thread's share of a parallel frame: its tracer, over its own page
// source (InMemoryPageSource holds a page table; a Tracer holds its stamps).
struct Lane {
  explicit Lane(const Database& db, const TraceOptions& options) : pages(db), tracer(db.header, pages, options) {}
  InMemoryPageSource pages;
  Tracer tracer;
  RayStats stats;
};

// Runs row(lane, y) for y in [first, last) on every lane, lane 0 on this
// thread; after each row this thread does, after_own_row(rows finished so
// far). See parallel_pieces for the order and for exceptions.
template <class Row, class AfterOwnRow>
void parallel_rows(std::vector<std::unique_ptr<Lane>>& lanes, int first, int last, const Row& row,
                   const AfterOwnRow& after_own_row) {
  std::atomic<int> finished{0};
  parallel_pieces(static_cast<unsigned>(lanes.size()), static_cast<std::size_t>(last - first),
                  [&](std::size_t i, unsigned worker) {
                    row(*lanes[worker], first + static_cast<int>(i));
                    const int done = finished.fetch_add(1, std::memory_order_relaxed) + 1;
                    if (worker == 0) after_own_row(done);
                  });
}

// Rows of SPD corner samples traced together: a band's samples are kept
// until its pixels are averaged, so this many rows of W+1 samples is the
// extra memory (16 KB a band at 512 pixels a row).
constexpr int kSampleBand = 32;

}  // namespace

std::vector<Color> render_frame(const Database& db, const TraceOptions& options, RayStats& stats, unsigned threads,
                                const std::function<void(int)>& progress) {
  const int w = db.header.camera.width, h = db.header.camera.height;
  std::vector<std::unique_ptr<Lane>> lanes;
  for (unsigned i = 0; i < std::max(1u, threads); ++i) lanes.push_back(std::make_unique<Lane>(db, options));
  std::vector<Color> out = frame_buffer(w, h);
  const auto report = [&](int rows) {
    if (progress) progress(rows);
  };
  if (!options.spd_procedure) {
    parallel_rows(
        lanes, 0, h,
        [&](Lane& lane, int y) {
          for (int x = 0; x < w; ++x) out[std::size_t(y) * w + x] = lane.tracer.trace_pixel(x, y, lane.stats);
        },
        report);
    report(h);  // the other threads may have done the last rows, or all of them
  } else {
    // Sample row r of the band starting at pixel row y0 is corner row y0 + r;
    // row 0 is the last row of the band before (or corner row 0, traced first).
    std::vector<Color> band(std::size_t(kSampleBand + 1) * (w + 1));
    const auto trace_row = [&](Lane& lane, int y0, int sy) {
      Color* samples = &band[std::size_t(sy - y0) * (w + 1)];
      for (int sx = 0; sx <= w; ++sx) samples[sx] = lane.tracer.trace_sample(sx, sy, lane.stats);
    };
    trace_row(*lanes[0], 0, 0);
    for (int y0 = 0; y0 < h; y0 += kSampleBand) {
      const int rows = std::min(kSampleBand, h - y0);
      parallel_rows(
          lanes, y0 + 1, y0 + rows + 1, [&](Lane& lane, int sy) { trace_row(lane, y0, sy); }, [](int) {});
      for (int y = y0; y < y0 + rows; ++y) {
        const Color* above = &band[std::size_t(y - y0) * (w + 1)];
        const Color* below = above + (w + 1);
        for (int x = 0; x < w; ++x)
          out[std::size_t(y) * w + x] = Tracer::average_corners(above[x], above[x + 1], below[x], below[x + 1]);
      }
      std::copy_n(&band[std::size_t(rows) * (w + 1)], w + 1, band.begin());  // the next band's first row
      report(y0 + rows);
    }
  }
  for (const auto& lane : lanes) stats += lane->stats;
  return out;
}

}  // namespace tracer
