// Uniform grid builder: choose the resolution, then fill the cell lists in two
// passes (count, then place) so memory is exactly the number of references.
#include "tracer/grid.hpp"

#include <algorithm>
#include <cmath>

namespace tracer {
namespace {

constexpr int kMaxDim = 1024;

void choose_dims(const Box3f& bounds, std::size_t prims, float density, int dims[3]) {
  const Vec3f e = bounds.extent();
  const double volume = std::max(1e-30, double(e.x) * e.y * e.z);
  const double cells = std::max(1.0, double(density) * double(prims));
  // Cubic cells of the side that gives the wanted count in the box's volume;
  // a flat box (zero volume) falls back to the longest side.
  double side = std::cbrt(volume / cells);
  const double longest = std::max({double(e.x), double(e.y), double(e.z), 1e-30});
  if (!(side > longest * 1e-4)) side = longest / std::cbrt(cells);
  for (int a = 0; a < 3; ++a)
    dims[a] = clamped_int(std::ceil(e[a] / side), 1, kMaxDim);
}

}  // namespace

void grid_cell_range(const Box3f& bounds, const int dims[3], const Box3f& b, int lo[3],
                     int hi[3]) {
  for (int a = 0; a < 3; ++a) {
    const float ext = bounds.hi[a] - bounds.lo[a];
    const float scale = ext > 0 ? dims[a] / ext : 0.0f;
    lo[a] = clamped_int((b.lo[a] - bounds.lo[a]) * scale, 0, dims[a] - 1);
    hi[a] = clamped_int((b.hi[a] - bounds.lo[a]) * scale, 0, dims[a] - 1);
  }
}

GridBuild build_grid(const std::vector<Box3f>& prim_bounds, const Box3f& bounds, float density) {
  GridBuild g;
  choose_dims(bounds, prim_bounds.size(), density, g.dims);
  const std::size_t ncells = std::size_t(g.dims[0]) * g.dims[1] * g.dims[2];
  g.cells.assign(ncells, GridCell{0, 0});
  auto for_each_cell = [&](const Box3f& b, auto&& fn) {
    int lo[3], hi[3];
    grid_cell_range(bounds, g.dims, b, lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x)
          fn(std::size_t(x) + std::size_t(g.dims[0]) * (y + std::size_t(g.dims[1]) * z));
  };
  for (const Box3f& b : prim_bounds) for_each_cell(b, [&](std::size_t c) { ++g.cells[c].count; });
  std::uint64_t total = 0;
  for (GridCell& c : g.cells) {
    c.first = static_cast<std::uint32_t>(total);
    total += c.count;
    c.count = 0;
  }
  g.lists.resize(total);
  for (std::uint32_t i = 0; i < prim_bounds.size(); ++i)
    for_each_cell(prim_bounds[i], [&](std::size_t c) {
      g.lists[g.cells[c].first + g.cells[c].count++] = i;
    });
  return g;
}

}  // namespace tracer
