// Uniform grid builder: choose the resolution, fill the top cells' lists in
// two passes (count, then place) so memory is exactly the number of
// references, then cut every dense top cell into a subgrid the same way.
//
// Why two levels: the paper's scenes are uneven (Tetra is a fractal, mostly
// empty; Teapot and Mountain are surfaces), so one resolution either walks
// many empty cells or tests many primitives in the occupied ones. A coarse
// top level crosses the empty space in few steps, and a subgrid sized to its
// own primitive count (kSubgridDensity cells each) keeps the tests per cell
// near a constant where the primitives are.
#include "tracer/grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tracer {
namespace {

constexpr int kMaxDim = 1024;

// Cubic cells of the side that gives `density` cells per primitive in the
// box (the cubic-root rule), so a cell's side follows the mean spacing of
// the primitives; a flat box (zero volume) falls back to the longest side.
void choose_dims(const Box3f& bounds, std::size_t prims, float density, int max_dim, int dims[3]) {
  const Vec3f e = bounds.extent();
  const double volume = std::max(1e-30, double(e.x) * e.y * e.z);
  const double cells = std::max(1.0, double(density) * double(prims));
  double side = std::cbrt(volume / cells);
  const double longest = std::max({double(e.x), double(e.y), double(e.z), 1e-30});
  if (!(side > longest * 1e-4)) side = longest / std::cbrt(cells);
  for (int a = 0; a < 3; ++a) dims[a] = clamped_int(std::ceil(e[a] / side), 1, max_dim);
}

// Lists of the primitives `ids` over a grid of `dims` cells on `bounds`,
// appended to `lists`; cells[base + c] gets cell c's range.
void fill_level(const std::vector<Box3f>& prim_bounds, const std::uint32_t* ids, std::size_t count, const Box3f& bounds,
                const int dims[3], std::size_t base, std::vector<GridCell>& cells, std::vector<std::uint32_t>& lists) {
  const auto for_each_cell = [&](const Box3f& b, auto&& fn) {
    int lo[3], hi[3];
    grid_cell_range(bounds, dims, b, lo, hi);
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x)
          fn(base + std::size_t(x) + std::size_t(dims[0]) * (y + std::size_t(dims[1]) * z));
  };
  const std::size_t ncells = std::size_t(dims[0]) * dims[1] * dims[2];
  for (std::size_t c = base; c < base + ncells; ++c) cells[c] = GridCell{0, 0};
  for (std::size_t i = 0; i < count; ++i) for_each_cell(prim_bounds[ids[i]], [&](std::size_t c) { ++cells[c].count; });
  std::uint64_t total = lists.size();
  for (std::size_t c = base; c < base + ncells; ++c) {
    if (total + cells[c].count >= std::numeric_limits<std::uint32_t>::max())
      throw DatabaseError("grid too large: more than 2^32 cell references");
    cells[c].first = static_cast<std::uint32_t>(total);
    total += cells[c].count;
    cells[c].count = 0;
  }
  lists.resize(total);
  for (std::size_t i = 0; i < count; ++i)
    for_each_cell(prim_bounds[ids[i]], [&](std::size_t c) { lists[cells[c].first + cells[c].count++] = ids[i]; });
}

}  // namespace

void grid_cell_range(const Box3f& bounds, const int dims[3], const Box3f& b, int lo[3], int hi[3]) {
  for (int a = 0; a < 3; ++a) {
    const float ext = bounds.hi[a] - bounds.lo[a];
    const float scale = ext > 0 ? dims[a] / ext : 0.0f;
    lo[a] = clamped_int((b.lo[a] - bounds.lo[a]) * scale, 0, dims[a] - 1);
    hi[a] = clamped_int((b.hi[a] - bounds.lo[a]) * scale, 0, dims[a] - 1);
  }
}

GridBuild build_grid(const std::vector<Box3f>& prim_bounds, const Box3f& bounds, float density) {
  GridBuild g;
  choose_dims(bounds, prim_bounds.size(), density, kMaxDim, g.dims);
  const std::size_t ntop = std::size_t(g.dims[0]) * g.dims[1] * g.dims[2];
  std::vector<std::uint32_t> all(prim_bounds.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  std::vector<GridCell> top(ntop);
  std::vector<std::uint32_t> top_lists;
  fill_level(prim_bounds, all.data(), all.size(), bounds, g.dims, 0, top, top_lists);
  all = {};

  g.cells.resize(ntop);
  g.lists.reserve(top_lists.size());
  for (std::size_t c = 0; c < ntop; ++c) {
    const GridCell tc = top[c];
    const int cell[3] = {int(c % g.dims[0]), int(c / g.dims[0] % g.dims[1]), int(c / g.dims[0] / g.dims[1])};
    const Box3f box = grid_cell_box(bounds, g.dims, cell);
    int sub[3] = {1, 1, 1};
    if (tc.count > kSubgridThreshold) choose_dims(box, tc.count, kSubgridDensity, kMaxSubgridDim, sub);
    if (sub[0] * sub[1] * sub[2] == 1) {
      if (tc.count >= kGridSubgridFlag) throw DatabaseError("grid too large: a cell lists 2^31 primitives");
      g.cells[c] = GridCell{static_cast<std::uint32_t>(g.lists.size()), tc.count};
      g.lists.insert(g.lists.end(), top_lists.begin() + tc.first, top_lists.begin() + tc.first + tc.count);
      continue;
    }
    const std::size_t base = g.cells.size();
    if (base >= std::numeric_limits<std::uint32_t>::max()) throw DatabaseError("grid too large: more than 2^32 cells");
    g.cells[c] = GridCell{static_cast<std::uint32_t>(base), encode_subgrid(sub)};
    g.cells.resize(base + std::size_t(sub[0]) * sub[1] * sub[2]);
    fill_level(prim_bounds, top_lists.data() + tc.first, tc.count, box, sub, base, g.cells, g.lists);
    ++g.subgrids;
  }
  // Renumber by first listing: a ray meets a cell's primitives together, so
  // together they take fewer pages and cache lines. Every primitive is
  // listed somewhere (its box lies in the bounds); any that were not would
  // come last.
  constexpr std::uint32_t kUnseen = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> new_id(prim_bounds.size(), kUnseen);
  g.order.reserve(prim_bounds.size());
  for (std::uint32_t& id : g.lists) {
    if (new_id[id] == kUnseen) {
      new_id[id] = static_cast<std::uint32_t>(g.order.size());
      g.order.push_back(id);
    }
    id = new_id[id];
  }
  for (std::uint32_t i = 0; i < prim_bounds.size(); ++i)
    if (new_id[i] == kUnseen) g.order.push_back(i);
  for (const GridCell& c : g.cells)
    if (!(c.count & kGridSubgridFlag)) std::sort(g.lists.begin() + c.first, g.lists.begin() + c.first + c.count);
  return g;
}

}  // namespace tracer
