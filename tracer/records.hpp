// The packed records of the scene database (database.hpp), the builders'
// (bvh.hpp, grid.hpp) output and the tracer's input: primitives, smooth
// normals, materials, four-wide BVH nodes and grid cells, each trivially
// copyable, of a fixed size that is a power of two (read with memcpy). And
// DatabaseError, which any of the builders throws for a bad build request.
#pragma once

#include <cstdint>
#include <stdexcept>

#include "tracer/geometry.hpp"

namespace tracer {

// A bad build request (page size, scene too large, ...); one-line message.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

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
// An empty cell (count 0) holds in `first` its distances to the nearest
// cell of its level that is not empty, each at least 1 and at most
// kGridDistanceMax: in bits 0-15 the chessboard distance d (every cell of
// the level within d - 1 of it on every axis is empty too), in bits 16-31
// the city-block distance e (so are the next e - 1 cells of any walk from
// it, which moves one axis a step at a time).
struct GridCell {
  std::uint32_t first;
  std::uint32_t count;
};
static_assert(sizeof(GridCell) == 8);
inline constexpr std::uint32_t kGridSubgridFlag = 1u << 31;
inline constexpr std::uint32_t kGridDistanceMax = 0xffff;
inline std::uint32_t encode_subgrid(const int dims[3]) {
  return kGridSubgridFlag | std::uint32_t(dims[0] - 1) | std::uint32_t(dims[1] - 1) << 8 |
         std::uint32_t(dims[2] - 1) << 16;
}
inline void decode_subgrid(std::uint32_t count, int dims[3]) {
  for (int a = 0; a < 3; ++a) dims[a] = int(count >> (8 * a) & 0xff) + 1;
}

}  // namespace tracer
