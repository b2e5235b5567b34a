// The paper's uniform voxel grid: the scene box cut into dims[0]*dims[1]*dims[2]
// cells, each listing the primitives whose box overlaps it (a primitive may be
// listed in many cells). Cell (x, y, z) is cells[x + dims[0] * (y + dims[1] * z)];
// its list is lists[first .. first + count), ascending primitive ids.
#pragma once

#include <cstdint>
#include <vector>

#include "tracer/database.hpp"
#include "tracer/geometry.hpp"

namespace tracer {

struct GridBuild {
  int dims[3] = {1, 1, 1};
  std::vector<GridCell> cells;
  std::vector<std::uint32_t> lists;
};

// About `density` cells per primitive, shaped to the box; bounds must contain
// every primitive box.
GridBuild build_grid(const std::vector<Box3f>& prim_bounds, const Box3f& bounds, float density);

// The cell index range [lo, hi] along each axis overlapped by box b.
void grid_cell_range(const Box3f& bounds, const int dims[3], const Box3f& b, int lo[3], int hi[3]);

}  // namespace tracer
