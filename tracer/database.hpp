// The paged scene database: the seam between the tracer and a (distributed)
// shared virtual memory. build_database() triangulates the Scene, builds the
// acceleration structure (BVH or uniform grid) and packs everything the
// tracer reads while tracing (primitives, smooth-shading normals, materials,
// BVH nodes, grid cells and their object lists) into fixed-size pages; the
// small DatabaseHeader (camera, background, lights, array layout, counts) is
// replicated everywhere and read directly. The tracer reads pages through a
// PageSource, whose contract is at its class.
// Layout invariants:
//  - Each array (Section) holds fixed-size records of a power of two <= 256
//    bytes and begins on a page boundary; page_size is a power of two >= 256,
//    so no record straddles two pages: record i of a section lives in page
//    first_page + i*size/page_size at offset (i*size) % page_size.
//  - References between records are array indices, never pointers; packing
//    is deterministic (details at build_database()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "tracer/geometry.hpp"
#include "tracer/scene.hpp"

namespace tracer {

using PageId = std::uint32_t;

// Where the tracer's reads go; the only access to the packed database.
// Contract: the pointer returned by page(id) is valid only until the next
// call to page() on the same source; readers copy out (memcpy) what they
// need before their next page() call and never keep a page pointer across
// one. So a source may evict any page inside page() (a one-page cache is
// enough), and fibers sharing a node's cache may switch inside page().
class PageSource {
 public:
  virtual ~PageSource() = default;
  // The page's page_size bytes; valid until the next page() call on this source.
  virtual const std::byte* page(PageId id) = 0;
};

// A bad build request (page size, scene too large, ...); one-line message.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Accel : std::uint32_t { bvh, grid };

// How BVH nodes are laid out in their pages (bvh.hpp): by treelets, each
// page a piece of the tree a ray goes down, or siblings together in
// depth-first order. Only page numbers differ, never the tree or the image.
enum class BvhLayout : std::uint32_t { treelet, depth_first };

struct BuildOptions {
  Accel accel = Accel::bvh;
  BvhLayout bvh_layout = BvhLayout::treelet;
  std::uint32_t page_size = 1024;  // bytes; a power of two in [256, 65536]
  int bvh_max_leaf = 4;            // primitives per BVH leaf at most
  int bvh_split_depth = 3;         // large triangles split into <= 2^depth references (0: none)
  float grid_density = 0.25f;      // top grid cells per primitive (approximately; grid.hpp)
  unsigned threads = 1;            // OS threads the build may use (0, 1: the caller's only)
};

// Throws DatabaseError unless page_size is a power of two in [256, 65536].
void validate_page_size(std::int64_t page_size);

// ---- Packed records (trivially copyable; read with memcpy) ----

enum class PrimKind : std::uint32_t { flat_triangle, smooth_triangle, sphere, cone };

// 64 bytes. Triangles: p0 = v0, p1 = e1, p2 = e2, p3 = unit polygon normal
// (from the polygon's first three vertices), aux = smooth-normal record index.
// Sphere: p0 = centre, p1.x = radius. Cone: p0 = base, p1 = apex,
// p2.x = base radius, p2.y = apex radius.
struct PrimRecord {
  PrimKind kind;
  std::uint32_t material;
  Vec3f p0, p1, p2, p3;
  std::uint32_t aux;
  std::uint32_t object;  // index of the Scene object it came from
};
static_assert(sizeof(PrimRecord) == 64);

// Vertex normals of a smooth triangle (64 bytes, padded).
struct NormalRecord {
  Vec3f n0, n1, n2;
  float pad[7];
};
static_assert(sizeof(NormalRecord) == 64);

struct MaterialRecord {
  Color color;
  float kd, ks, shine, transmittance, ior;
};
static_assert(sizeof(MaterialRecord) == 32);

// Four-wide BVH node: the boxes of up to four children in structure-of-arrays
// form, so one record read decides which children a ray visits and the four
// slab tests run side by side. Lane i: child[i] is a node index when
// count[i] == 0, else the first of count[i] consecutive primitives. An unused
// lane has an empty box (lo > hi), which no ray meets.
struct BvhNode {
  float lo[3][4];  // [axis][lane]
  float hi[3][4];
  std::uint32_t child[4];
  std::uint32_t count[4];
};
static_assert(sizeof(BvhNode) == 128);

// A grid cell: `count` primitive ids starting at `first` in the cell-list
// section; or, for a top cell with kGridSubgridFlag set in `count`, a subgrid
// over the cell's box whose cells start at record `first` of the cell section,
// its dimensions (1..256 each) in count's bits 0-7, 8-15 and 16-23, less one.
struct GridCell {
  std::uint32_t first;
  std::uint32_t count;
};
static_assert(sizeof(GridCell) == 8);
inline constexpr std::uint32_t kGridSubgridFlag = 1u << 31;
inline std::uint32_t encode_subgrid(const int dims[3]) {
  return kGridSubgridFlag | std::uint32_t(dims[0] - 1) | std::uint32_t(dims[1] - 1) << 8 |
         std::uint32_t(dims[2] - 1) << 16;
}
inline void decode_subgrid(std::uint32_t count, int dims[3]) {
  for (int a = 0; a < 3; ++a) dims[a] = int(count >> (8 * a) & 0xff) + 1;
}

enum class Section : int { prims, normals, materials, bvh_nodes, grid_cells, grid_lists, count };

struct SectionLayout {
  PageId first_page = 0;
  std::uint32_t record_size = 0;
  std::uint32_t record_count = 0;
};

struct LightRecord {
  Vec3f position;
  Color color;  // already scaled by the light intensity
};

// Replicated on every processor ("process code" in the paper); read directly.
struct DatabaseHeader {
  std::string scene_name;
  Camera camera;
  Color background;
  std::vector<LightRecord> lights;
  std::uint32_t page_size = 0;
  std::uint32_t page_shift = 0;  // log2(page_size)
  std::uint32_t page_count = 0;
  SectionLayout sections[static_cast<int>(Section::count)];
  Accel accel = Accel::bvh;
  Box3f bounds;              // of all primitives
  BvhNode bvh_root;          // copy of node 0 (unused when primitive_count == 0)
  std::uint32_t bvh_depth = 1;  // longest root-to-leaf path in nodes (sizes traversal stacks)
  int grid_dims[3] = {0, 0, 0};
  float epsilon = 1e-4f;     // self-intersection offset, scaled to the scene
  std::uint64_t polygon_count = 0;  // "p" + "pp" entities of the scene
  std::uint64_t object_count = 0;   // scene objects
  std::uint64_t primitive_count = 0;  // after triangulation

  const SectionLayout& section(Section s) const { return sections[static_cast<int>(s)]; }
  std::uint64_t bytes() const { return std::uint64_t{page_count} * page_size; }
};

struct BuildStats {
  double triangulate_seconds = 0;
  double accel_seconds = 0;  // BVH or grid build
  double pack_seconds = 0;
  std::uint64_t bvh_nodes = 0;
  std::uint64_t bvh_references = 0;  // primitive copies in BVH leaves (>= primitives)
  std::uint64_t grid_cells = 0;
  std::uint64_t grid_references = 0;
  std::uint64_t grid_subgrids = 0;  // top cells cut into a grid of their own
  std::uint64_t payload_bytes = 0;  // record bytes, without page padding
};

struct Database {
  DatabaseHeader header;
  std::vector<std::vector<std::byte>> pages;  // header.page_count pages of page_size bytes
  BuildStats stats;
};

// Builds and packs; throws DatabaseError for a bad page size or a scene too
// large for 32-bit references, std::invalid_argument for an empty camera.
// References between records are array indices (global object ids). Packing
// is deterministic and the acceleration structure is built before packing,
// so the floats the tracer computes with do not depend on page size (the
// treelet layout numbers BVH nodes by pages, but the tree is the same), nor
// on BuildOptions::threads: every thread count gives the same pages.
Database build_database(const Scene& scene, const BuildOptions& options = {});

// The single-process page source: every page in memory, shared read-only.
// It keeps a flat table of page addresses: one load per page() call.
class InMemoryPageSource final : public PageSource {
 public:
  explicit InMemoryPageSource(const Database& db) {
    pages_.reserve(db.pages.size());
    for (const auto& p : db.pages) pages_.push_back(p.data());
  }
  const std::byte* page(PageId id) override { return pages_[id]; }

 private:
  std::vector<const std::byte*> pages_;
};

}  // namespace tracer
