// The paper's uniform voxel grid, two levels: the scene box cut into
// dims[0]*dims[1]*dims[2] top cells, each listing the primitives whose box
// overlaps it or, past kSubgridThreshold of them, cut into a grid of its
// own (at most kMaxSubgridDim cells a side) whose cells list them.
// Invariants:
//  - Top cell (x, y, z) is cells[x + dims[0] * (y + dims[1] * z)]; the cells
//    of a subgrid follow all top cells, in the same x-fastest order,
//    starting at the top cell's `first` (see GridCell in records.hpp).
//  - A list cell's primitives are lists[first .. first + count), ascending
//    ids; an empty cell holds instead its distances to the nearest occupied
//    cell of its level (records.hpp), by which the walk skips empty space.
//  - Primitives are renumbered in the order the cells first list them
//    (`order`), so the primitives of a cell lie side by side in their pages.
//  - Builder and tracer compute a cell's box alike (grid_cell_box, below);
//    the build is sequential and depends only on its inputs.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tracer/geometry.hpp"
#include "tracer/records.hpp"

namespace tracer {

inline constexpr std::uint32_t kSubgridThreshold = 8;  // primitives a top cell holds before it is cut
inline constexpr int kMaxSubgridDim = 64;              // subgrid cells per axis at most
inline constexpr float kSubgridDensity = 1.0f;         // subgrid cells per primitive of its top cell

struct GridBuild {
  int dims[3] = {1, 1, 1};
  std::vector<GridCell> cells;
  std::vector<std::uint32_t> lists;
  std::uint64_t subgrids = 0;
  std::vector<std::uint32_t> order;  // order[new id] = the primitive's index in prim_bounds
};

// About `density` top cells per primitive, shaped to the box, cut into
// subgrids where dense; bounds must contain every primitive box.
// prims[i] has box prim_bounds[i].
GridBuild build_grid(std::span<const PrimRecord> prims, std::span<const Box3f> prim_bounds, const Box3f& bounds,
                     float density);

// The cell index range [lo, hi] along each axis overlapped by box b.
void grid_cell_range(const Box3f& bounds, const int dims[3], const Box3f& b, int lo[3], int hi[3]);

// The box of cell `cell` of a grid of `dims` cells over `bounds`: a cell's
// box is grid_cell_box(parent box, parent dims, its coordinates), the same
// float arithmetic in the builder and the tracer; a primitive is listed in
// every cell of a level that its box overlaps by grid_cell_range and that
// the primitive itself may overlap (a conservative test).
inline Box3f grid_cell_box(const Box3f& bounds, const int dims[3], const int cell[3]) {
  Box3f b;
  for (int a = 0; a < 3; ++a) {
    const float size = (bounds.hi[a] - bounds.lo[a]) / dims[a];
    b.lo[a] = bounds.lo[a] + cell[a] * size;
    b.hi[a] = cell[a] + 1 == dims[a] ? bounds.hi[a] : bounds.lo[a] + (cell[a] + 1) * size;
  }
  return b;
}

}  // namespace tracer
