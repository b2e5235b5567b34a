// build_database: triangulate, build the acceleration structure, pack pages.
#include "tracer/database.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <type_traits>

#include "tracer/bvh.hpp"
#include "tracer/grid.hpp"
#include "tracer/huge_pages.hpp"
#include "tracer/parallel.hpp"

namespace tracer {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Vec3f to_f(const Vec3d& v) { return static_cast<Vec3f>(v); }

// Primitives in scene order with their boxes, before any acceleration structure.
struct Flattened {
  BigVector<PrimRecord> prims;
  BigVector<NormalRecord> normals;
  BigVector<Box3f> bounds;
};

// Widen a box by a few float ulps of its coordinates, so that float rounding
// in the intersection routines never puts a hit outside its primitive's box.
Box3f padded(const Box3f& b) { return widened(b, 1e-6f); }

void add_polygon(Flattened& f, std::span<const Vec3d> v, const std::vector<Vec3d>* normals,
                 std::uint32_t material, std::uint32_t object) {
  const Vec3d n = cross(v[1] - v[0], v[2] - v[0]);
  if (!(length(n) > 0)) return;  // first three vertices collinear: no plane, nothing visible
  const Vec3f unit_n = to_f(normalize(n));
  for (const auto& tri : triangulate_polygon(v)) {
    PrimRecord r{};
    r.kind = normals ? PrimKind::smooth_triangle : PrimKind::flat_triangle;
    r.material = material;
    r.object = object;
    r.p0 = to_f(v[tri[0]]);
    r.p1 = to_f(v[tri[1]] - v[tri[0]]);
    r.p2 = to_f(v[tri[2]] - v[tri[0]]);
    r.p3 = unit_n;
    if (normals) {
      NormalRecord nr{};
      nr.n0 = to_f(normalize((*normals)[tri[0]]));
      nr.n1 = to_f(normalize((*normals)[tri[1]]));
      nr.n2 = to_f(normalize((*normals)[tri[2]]));
      r.aux = static_cast<std::uint32_t>(f.normals.size());
      f.normals.push_back(nr);
    }
    Box3f b;
    for (int k = 0; k < 3; ++k) b.extend(to_f(v[tri[k]]));
    f.prims.push_back(r);
    f.bounds.push_back(padded(b));
  }
}

// Objects flattened in chunks of this many, a chunk on one of the build's
// threads; the chunks join in order, so the result is the one-thread one.
constexpr std::size_t objects_per_chunk = 4096;
constexpr std::size_t chunks_per_wave = 4;  // of a scene consumed, freed and given back after each

// Room for every primitive the scene's objects can make (a polygon of n
// vertices n - 2 triangles, fewer only if degenerate), so that the arrays
// are never moved while they grow, which would hold two copies at once.
void reserve_for(const Scene& scene, Flattened& f) {
  std::size_t prims = 0, normals = 0;
  for (const Object& o : scene.objects) {
    if (const auto* p = std::get_if<Polygon>(&o.shape)) {
      prims += p->vertices.size() - 2;
    } else if (const auto* pp = std::get_if<Patch>(&o.shape)) {
      prims += pp->vertices.size() - 2;
      normals += pp->vertices.size() - 2;
    } else {
      ++prims;
    }
  }
  f.prims.reserve(prims);
  f.bounds.reserve(prims);
  f.normals.reserve(normals);
}

void flatten_range(const Scene& scene, std::size_t begin, std::size_t end, Flattened& f) {
  for (auto i = static_cast<std::uint32_t>(begin); i < end; ++i) {
    const Object& o = scene.objects[i];
    PrimRecord r{};
    r.material = o.material;
    r.object = i;
    if (const auto* s = std::get_if<Sphere>(&o.shape)) {
      r.kind = PrimKind::sphere;
      r.p0 = to_f(s->center);
      r.p1.x = static_cast<float>(s->radius);
      const float ar = std::fabs(r.p1.x);
      f.bounds.push_back(padded({r.p0 - Vec3f{ar, ar, ar}, r.p0 + Vec3f{ar, ar, ar}}));
      f.prims.push_back(r);
    } else if (const auto* c = std::get_if<Cone>(&o.shape)) {
      r.kind = PrimKind::cone;
      r.p0 = to_f(c->base);
      r.p1 = to_f(c->apex);
      r.p2 = {static_cast<float>(c->base_radius), static_cast<float>(c->apex_radius), 0};
      f.bounds.push_back(padded(cone_bounds({r.p0, r.p1, r.p2.x, r.p2.y})));
      f.prims.push_back(r);
    } else if (const auto* p = std::get_if<Polygon>(&o.shape)) {
      add_polygon(f, points(p->vertices), nullptr, o.material, i);
    } else if (const auto* pp = std::get_if<Patch>(&o.shape)) {
      add_polygon(f, points(pp->vertices), &pp->normals, o.material, i);
    }
  }
}

// Appends part's records to f and frees them; a smooth triangle's aux
// indexes the normals, which now follow those of the parts before.
void append(Flattened& f, Flattened& part) {
  const auto offset = static_cast<std::uint32_t>(f.normals.size());
  for (PrimRecord& r : part.prims)
    if (r.kind == PrimKind::smooth_triangle) r.aux += offset;
  f.prims.insert(f.prims.end(), part.prims.begin(), part.prims.end());
  f.bounds.insert(f.bounds.end(), part.bounds.begin(), part.bounds.end());
  f.normals.insert(f.normals.end(), part.normals.begin(), part.normals.end());
  part = Flattened{};
}

// Chunks [first, last) of the objects into parts[first..last), on the build's threads.
void flatten_chunks(const Scene& scene, std::size_t first, std::size_t last, std::vector<Flattened>& parts,
                    unsigned threads) {
  const std::size_t n = scene.objects.size();
  const auto objects = [n](std::size_t c) { return std::min(n, c * objects_per_chunk); };  // before chunk c
  parallel_pieces(threads, last - first, [&](std::size_t k) {
    flatten_range(scene, objects(first + k), objects(first + k + 1), parts[first + k]);
  });
}

// The parts joined in order into arrays of their exact size; each part is
// freed once copied, and the freed memory given back every wave of parts,
// so that the join holds little more than one copy.
Flattened join(std::vector<Flattened>& parts) {
  std::size_t prims = 0, normals = 0;
  for (const Flattened& part : parts) {
    prims += part.prims.size();
    normals += part.normals.size();
  }
  Flattened f;
  f.prims.reserve(prims);
  f.bounds.reserve(prims);
  f.normals.reserve(normals);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    append(f, parts[k]);
    if ((k + 1) % chunks_per_wave == 0) return_freed_heap();
  }
  return_freed_heap();
  return f;
}

std::size_t chunk_count(const Scene& scene) {
  return (scene.objects.size() + objects_per_chunk - 1) / objects_per_chunk;
}

// A scene kept: one pass on one thread, or all chunks at once and joined.
Flattened flatten(const Scene& scene, unsigned threads) {
  const std::size_t chunks = chunk_count(scene);
  if (threads <= 1 || chunks <= 1) {
    Flattened f;
    reserve_for(scene, f);
    flatten_range(scene, 0, scene.objects.size(), f);
    return f;
  }
  std::vector<Flattened> parts(chunks);
  flatten_chunks(scene, 0, chunks, parts, threads);
  return join(parts);
}

// A scene consumed: its chunks a wave at a time from the last to the first,
// and after each wave the wave's objects are destroyed and their memory,
// the objects' storage past those left and the vertex arrays, given back.
// So the scene shrinks as the records grow, and the peak is about the
// larger of the two and one wave. The objects left are those of the chunks
// still to flatten, which the build's threads read while the calling thread
// alone frees (threads freeing into one heap at once wait for each other).
Flattened flatten(Scene& scene, unsigned threads) {
  std::vector<Flattened> parts(chunk_count(scene));
  for (std::size_t last = parts.size(); last > 0;) {
    const std::size_t first = last > chunks_per_wave ? last - chunks_per_wave : 0;
    flatten_chunks(scene, first, last, parts, threads);
    truncate_and_give_back(scene.objects, first * objects_per_chunk);
    return_freed_heap();
    last = first;
  }
  BigVector<Object>().swap(scene.objects);  // its storage unmapped before the join maps the records'
  return join(parts);
}

// Appends sections of fixed-size records, each starting on a fresh page.
// Pages are filled in pieces of kPagesPerPiece on the build's threads; each
// page's bytes depend only on the records.
class Packer {
 public:
  Packer(std::uint32_t page_size, unsigned threads) : page_size_(page_size), threads_(threads) {}

  template <class Records>
  SectionLayout add(const Records& records, const char* what) {
    using T = typename Records::value_type;
    return add_each<T>(records.size(), what, [&](std::size_t i, T& out) { out = records[i]; });
  }

  // A section of `count` records, record i made by fill(i, T&) as its page
  // is filled, so a permuted section needs no copy of its own. Given
  // `consumed`, the pages are filled a batch at a time from the last, and
  // consumed(k) is called once the records from k on are packed.
  template <class T, class Fill, class Consumed = std::nullptr_t>
  SectionLayout add_each(std::size_t count, const char* what, const Fill& fill, const Consumed& consumed = nullptr) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (sizeof(T) > page_size_)
      throw DatabaseError("page size " + std::to_string(page_size_) + " is too small for a " +
                          what + " record of " + std::to_string(sizeof(T)) + " bytes");
    SectionLayout s{static_cast<PageId>(pages_.size()), sizeof(T), static_cast<std::uint32_t>(count)};
    const std::size_t per_page = page_size_ / sizeof(T);  // both powers of two: no record spans two pages
    const std::size_t npages = (count + per_page - 1) / per_page;
    if (pages_.size() + npages > std::numeric_limits<PageId>::max())
      throw DatabaseError("scene too large: more than 2^32 pages");
    const std::size_t base = pages_.size();
    pages_.resize(base + npages);
    const std::size_t pieces = (npages + kPagesPerPiece - 1) / kPagesPerPiece;
    const auto fill_piece = [&](std::size_t piece) {
      T record;
      for (std::size_t p = piece * kPagesPerPiece; p < std::min(npages, (piece + 1) * kPagesPerPiece); ++p) {
        std::vector<std::byte> page(page_size_, std::byte{0});
        for (std::size_t i = p * per_page, end = std::min(count, (p + 1) * per_page); i < end; ++i) {
          fill(i, record);
          std::memcpy(page.data() + (i - p * per_page) * sizeof(T), &record, sizeof(T));
        }
        pages_[base + p] = std::move(page);
      }
    };
    if constexpr (std::is_null_pointer_v<Consumed>) {
      parallel_pieces(threads_, pieces, fill_piece);
    } else {
      for (std::size_t last = pieces; last > 0;) {
        const std::size_t first = last > kPiecesPerBatch ? last - kPiecesPerBatch : 0;
        parallel_pieces(threads_, last - first, [&](std::size_t k) { fill_piece(first + k); });
        consumed(first * kPagesPerPiece * per_page);
        last = first;
      }
    }
    payload_ += count * sizeof(T);
    return s;
  }

  std::vector<std::vector<std::byte>> take() { return std::move(pages_); }
  std::uint64_t payload() const { return payload_; }

 private:
  static constexpr std::size_t kPagesPerPiece = 256;  // filled together on one thread
  static constexpr std::size_t kPiecesPerBatch = 16;  // of a consumed section, before its records are freed
  std::uint32_t page_size_;
  unsigned threads_;
  std::vector<std::vector<std::byte>> pages_;
  std::uint64_t payload_ = 0;
};

// The normal records of the smooth triangles in an acceleration structure's
// leaf order (a primitive listed in several leaves has its record copied
// for each): each leaf position's new normal index and each new record's
// source, worked out in pieces on the build's threads (a first pass counts
// each piece's smooth triangles, so every piece knows where its normals
// start). No normals, no index array.
struct LeafOrder {
  BigVector<std::uint32_t> normal;      // normal[i]: its normal record's new index (smooth triangles)
  BigVector<std::uint32_t> normal_src;  // normal_src[k]: the flattened normal record of new index k
};

LeafOrder leaf_order(const Flattened& f, std::span<const std::uint32_t> order, unsigned threads) {
  constexpr std::size_t piece_size = 1 << 16;
  const std::size_t pieces = (order.size() + piece_size - 1) / piece_size;
  std::vector<std::size_t> first_normal(pieces + 1, 0);
  parallel_pieces(threads, pieces, [&](std::size_t p) {
    std::size_t smooth = 0;
    for (std::size_t i = p * piece_size; i < std::min(order.size(), (p + 1) * piece_size); ++i)
      smooth += f.prims[order[i]].kind == PrimKind::smooth_triangle;
    first_normal[p + 1] = smooth;
  });
  for (std::size_t p = 0; p < pieces; ++p) first_normal[p + 1] += first_normal[p];
  const std::size_t normals = first_normal[pieces];
  LeafOrder out{BigVector<std::uint32_t>(normals > 0 ? order.size() : 0), BigVector<std::uint32_t>(normals)};
  parallel_pieces(threads, pieces, [&](std::size_t p) {
    std::size_t next_normal = first_normal[p];
    for (std::size_t i = p * piece_size; i < std::min(order.size(), (p + 1) * piece_size); ++i) {
      const PrimRecord& r = f.prims[order[i]];
      if (r.kind != PrimKind::smooth_triangle) continue;
      out.normal_src[next_normal] = r.aux;
      out.normal[i] = static_cast<std::uint32_t>(next_normal++);
    }
  });
  return out;
}

// The primitives put in leaf order where they lie, for packing from the
// last page to the first with each batch's records freed once packed, so
// that the primitives are held about once. Leaf position i takes either
// the first leaf entry of its primitive, whose record is moved in place to
// prims[source[i]], first entries in leaf order; or a later entry of a
// primitive copied into several leaves (split references), whose record is
// copied out beforehand to copies[source[i] - kCopy]. Primitives no leaf
// names go after the first entries, and are freed with the first batch.
class LeafRecords {
 public:
  static constexpr std::uint32_t kCopy = 1u << 31;

  // Takes `order` over as its source array.
  static LeafRecords make(BigVector<PrimRecord>& prims, std::span<std::uint32_t> order) {
    if (order.size() >= kCopy) throw DatabaseError("scene too large: 2^31 leaf entries or more");
    LeafRecords out(prims);
    const std::size_t n = prims.size();
    std::vector<bool> named(n);
    std::vector<std::uint32_t> first_of;  // first_of[j]: the primitive moved to prims[j]
    first_of.reserve(n);
    for (std::uint32_t& k : order) {
      if (named[k]) {
        out.copies_.push_back(prims[k]);
        k = kCopy + static_cast<std::uint32_t>(out.copies_.size() - 1);
      } else {
        named[k] = true;
        first_of.push_back(k);
        k = static_cast<std::uint32_t>(first_of.size() - 1);
      }
    }
    out.firsts_ = first_of.size();
    for (std::uint32_t k = 0; k < n; ++k)
      if (!named[k]) first_of.push_back(k);
    permute(prims, first_of);
    out.source_ = order;
    return out;
  }

  const PrimRecord& at(std::size_t i) const {
    const std::uint32_t k = source_[i];
    return k >= kCopy ? copies_[k - kCopy] : prims_[k];
  }
  // Leaf positions from `packed_from` on are packed: frees their records.
  void packed(std::size_t packed_from) {
    std::size_t keep = firsts_;  // first entries before packed_from: the rank of the next one
    for (std::size_t i = packed_from; i < source_.size(); ++i)
      if (source_[i] < kCopy) {
        keep = source_[i];
        break;
      }
    truncate_and_give_back(prims_, keep);
  }

 private:
  explicit LeafRecords(BigVector<PrimRecord>& prims) : prims_(prims) {}

  // prims[j] becomes what was prims[from[j]], a cycle of the permutation at
  // a time: no second copy.
  static void permute(BigVector<PrimRecord>& prims, const std::vector<std::uint32_t>& from) {
    std::vector<bool> done(prims.size());
    for (std::size_t start = 0; start < prims.size(); ++start) {
      if (done[start]) continue;
      const PrimRecord first = prims[start];
      for (std::size_t i = start;;) {
        done[i] = true;
        if (from[i] == start) {
          prims[i] = first;
          break;
        }
        prims[i] = prims[from[i]];
        i = from[i];
      }
    }
  }

  BigVector<PrimRecord>& prims_;
  std::vector<PrimRecord> copies_;
  std::span<const std::uint32_t> source_;
  std::size_t firsts_ = 0;
};

// Packs the primitives and normals in leaf order: the sections' last two.
// The leaf order `order` is used up (see LeafRecords).
void pack_leaf_order(Packer& packer, Flattened& f, std::span<std::uint32_t> order, const LeafOrder& leaves,
                     SectionLayout* sections) {
  LeafRecords records = LeafRecords::make(f.prims, order);
  sections[int(Section::prims)] = packer.add_each<PrimRecord>(
      order.size(), "primitive",
      [&](std::size_t i, PrimRecord& r) {
        r = records.at(i);
        if (r.kind == PrimKind::smooth_triangle) r.aux = leaves.normal[i];
      },
      [&](std::size_t packed_from) { records.packed(packed_from); });
  sections[int(Section::normals)] =
      packer.add_each<NormalRecord>(leaves.normal_src.size(), "normal", [&](std::size_t k, NormalRecord& n) {
        n = f.normals[leaves.normal_src[k]];
      });
}

std::vector<MaterialRecord> material_records(const Scene& scene) {
  std::vector<MaterialRecord> out;
  for (const Material& m : scene.materials)
    out.push_back({m.color, float(m.kd), float(m.ks), float(m.shine), float(m.transmittance),
                   float(m.ior)});
  if (out.empty()) out.push_back({{1, 1, 1}, 1, 0, 0, 0, 1});
  return out;
}

// What the header counts of a scene's objects, taken before they are flattened.
struct ObjectCounts {
  std::size_t polygons = 0;
  std::size_t objects = 0;
};

void fill_header(DatabaseHeader& h, const Scene& scene, ObjectCounts counts, const Flattened& f,
                 const BuildOptions& opt) {
  h.scene_name = scene.name;
  h.camera = scene.camera;
  h.background = scene.background;
  // SPD's convention: each light has intensity 1/sqrt(number of lights).
  const float intensity = scene.lights.empty() ? 1.0f : 1.0f / std::sqrt(float(scene.lights.size()));
  for (const Light& l : scene.lights) h.lights.push_back({to_f(l.position), l.color * intensity});
  h.page_size = opt.page_size;
  h.page_shift = static_cast<std::uint32_t>(std::countr_zero(opt.page_size));
  h.accel = opt.accel;
  for (const Box3f& b : f.bounds) h.bounds.extend(b);
  const float diag = h.bounds.empty() ? 1.0f : length(h.bounds.extent());
  h.epsilon = std::max(diag * 2e-5f, 1e-6f);
  h.polygon_count = counts.polygons;
  h.object_count = counts.objects;
  h.primitive_count = f.prims.size();
}

void check_request(const Scene& scene, const BuildOptions& opt) {
  validate_page_size(opt.page_size);
  if (scene.camera.width < 1 || scene.camera.height < 1)
    throw std::invalid_argument("image size must be at least 1x1");
}

Database build_flattened(const Scene& scene, ObjectCounts counts, Flattened f, const BuildOptions& opt,
                         Clock::time_point t0) {
  Database db;
  if (f.prims.size() >= std::numeric_limits<std::uint32_t>::max())
    throw DatabaseError("scene too large: more than 2^32 primitives");
  fill_header(db.header, scene, counts, f, opt);
  db.stats.triangulate_seconds = seconds_since(t0);

  t0 = Clock::now();
  DatabaseHeader& h = db.header;
  Packer packer(opt.page_size, opt.threads);
  auto& sec = h.sections;
  sec[int(Section::materials)] = packer.add(material_records(scene), "material");
  // Each array is freed as soon as the build is done with it, so that a big
  // scene's peak holds as few of them at once as the steps allow.
  const auto release = [](auto& v) { std::remove_reference_t<decltype(v)>().swap(v); };
  if (opt.accel == Accel::bvh) {
    BuildRefs refs = split_large_triangles(f.prims, f.bounds, opt.bvh_split_depth);
    release(f.bounds);
    BvhBuild bvh = build_bvh(refs, opt.bvh_max_leaf, {.threads = opt.threads});
    release(refs.bounds);
    release(refs.triangle);
    return_freed_heap();  // the binary tree's, before the pages are made
    if (opt.bvh_layout == BvhLayout::treelet) lay_out_treelets(bvh, opt.page_size / sizeof(BvhNode));
    for (std::uint32_t& k : bvh.order) k = refs.prim[k];
    db.stats.bvh_references = refs.prim.size();
    release(refs.prim);
    const LeafOrder leaves = leaf_order(f, bvh.order, opt.threads);
    db.stats.accel_seconds = seconds_since(t0);
    t0 = Clock::now();
    h.bvh_root = bvh.nodes[0];
    h.bvh_depth = bvh.depth;
    db.stats.bvh_nodes = bvh.nodes.size();
    sec[int(Section::bvh_nodes)] = packer.add(bvh.nodes, "BVH node");
    release(bvh.nodes);
    pack_leaf_order(packer, f, bvh.order, leaves, sec);
  } else {
    GridBuild g = build_grid(f.prims, f.bounds, h.bounds, opt.grid_density);
    const LeafOrder leaves = leaf_order(f, g.order, opt.threads);
    db.stats.accel_seconds = seconds_since(t0);
    t0 = Clock::now();
    std::copy(g.dims, g.dims + 3, h.grid_dims);
    db.stats.grid_cells = g.cells.size();
    db.stats.grid_references = g.lists.size();
    db.stats.grid_subgrids = g.subgrids;
    sec[int(Section::grid_cells)] = packer.add(g.cells, "grid cell");
    sec[int(Section::grid_lists)] = packer.add(g.lists, "grid list");
    pack_leaf_order(packer, f, g.order, leaves, sec);
  }
  db.stats.payload_bytes = packer.payload();
  db.pages = packer.take();
  h.page_count = static_cast<std::uint32_t>(db.pages.size());
  db.stats.pack_seconds = seconds_since(t0);
  return db;
}

}  // namespace

void validate_page_size(std::int64_t page_size) {
  if (page_size < 256 || page_size > 65536 || !std::has_single_bit(static_cast<std::uint64_t>(page_size)))
    throw DatabaseError("page size " + std::to_string(page_size) +
                        " is not a power of two from 256 to 65536");
}

Database build_database(const Scene& scene, const BuildOptions& opt) {
  check_request(scene, opt);
  const auto t0 = Clock::now();
  const ObjectCounts counts{scene.polygon_count(), scene.objects.size()};
  return build_flattened(scene, counts, flatten(scene, opt.threads), opt, t0);
}

Database build_database(Scene&& scene, const BuildOptions& opt) {
  check_request(scene, opt);
  const auto t0 = Clock::now();
  const ObjectCounts counts{scene.polygon_count(), scene.objects.size()};
  Flattened f = flatten(scene, opt.threads);
  return build_flattened(scene, counts, std::move(f), opt, t0);
}

}  // namespace tracer
