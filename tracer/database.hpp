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
#include <string>
#include <vector>

#include "tracer/geometry.hpp"
#include "tracer/records.hpp"
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
// The same database from a scene it consumes: the objects are flattened
// from the last and freed as they go, so that a large scene's peak memory
// holds its geometry or its primitives, not both (the primitives are then
// packed the same way, freed as their pages are made). The scene keeps its
// name, camera, lights, materials and background; its objects are gone.
Database build_database(Scene&& scene, const BuildOptions& options = {});

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
