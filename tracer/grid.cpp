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
//
// The densities (grid.hpp, and BuildOptions::grid_density for the top) were
// chosen with tracer_bench --grid on the four paper scenes: 0.25 top cells
// and 1 subgrid cell per primitive, subgrids above 8 primitives. Denser
// grids list more references and walk more cells for fewer tests, and came
// out no faster (2 and 4 subgrid cells a primitive: within 5%); a single
// level at 2 cells a primitive, the old rule, was 1.3-2x slower.
#include "tracer/grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
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

// Whether the primitive may meet the box: exactly for a triangle (the
// separating axes of Akenine-Moeller's test: the box's three, the
// triangle's normal, the nine cross products of edges and box axes) and a
// sphere, conservatively for a cone (its axis within the larger radius of
// the box's centre, plus the box's half diagonal). In double precision on a
// box widened by a part in a thousand, so that rounding never drops a cell
// the primitive touches; a wrongly kept cell only costs a test.
bool may_overlap(const PrimRecord& p, const Box3f& box) {
  Vec3d c, h;
  for (int a = 0; a < 3; ++a) {
    c[a] = 0.5 * (double(box.lo[a]) + double(box.hi[a]));
    h[a] = 0.5 * (double(box.hi[a]) - double(box.lo[a]));
    h[a] = h[a] * 1.001 + 1e-30;
  }
  const auto d = [](const Vec3f& v) { return Vec3d{v.x, v.y, v.z}; };
  switch (p.kind) {
    case PrimKind::flat_triangle:
    case PrimKind::smooth_triangle: {
      const Vec3d v[3] = {d(p.p0) - c, d(p.p0) + d(p.p1) - c, d(p.p0) + d(p.p2) - c};
      const auto separated = [&](const Vec3d& axis) {
        const double r = h.x * std::abs(axis.x) + h.y * std::abs(axis.y) + h.z * std::abs(axis.z);
        const double p0 = dot(axis, v[0]), p1 = dot(axis, v[1]), p2 = dot(axis, v[2]);
        return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
      };
      const Vec3d e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
      if (separated(cross(e[0], e[1]))) return false;
      const Vec3d units[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      for (const Vec3d& u : units) {
        if (separated(u)) return false;
        for (const Vec3d& edge : e)
          if (separated(cross(u, edge))) return false;
      }
      return true;
    }
    case PrimKind::sphere: {
      const Vec3d q = d(p.p0) - c;
      double dist2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double out = std::max(0.0, std::abs(q[a]) - h[a]);
        dist2 += out * out;
      }
      const double r = std::abs(double(p.p1.x)) * 1.001;
      return dist2 <= r * r;
    }
    case PrimKind::cone: {
      const Vec3d a = d(p.p0) - c, b = d(p.p1) - c, ab = b - a;
      const double len2 = dot(ab, ab);
      const double t = len2 > 0 ? std::clamp(-dot(a, ab) / len2, 0.0, 1.0) : 0.0;
      const Vec3d nearest = a + ab * t;
      const double reach = std::max(std::abs(double(p.p2.x)), std::abs(double(p.p2.y))) + length(h);
      return dot(nearest, nearest) <= reach * reach * 1.001;
    }
  }
  return true;
}

// Lists of the primitives `ids` over a grid of `dims` cells on `bounds`,
// appended to `lists`; cells[base + c] gets cell c's range. A primitive is
// listed in the cells of its box's range that it may overlap, or in all of
// them should the test keep none.
void fill_level(std::span<const PrimRecord> prims, std::span<const Box3f> prim_bounds, const std::uint32_t* ids,
                std::size_t count, const Box3f& bounds, const int dims[3], std::size_t base,
                std::vector<GridCell>& cells, std::vector<std::uint32_t>& lists) {
  std::vector<std::size_t> kept;
  const auto for_each_cell = [&](std::uint32_t id, auto&& fn) {
    int lo[3], hi[3];
    grid_cell_range(bounds, dims, prim_bounds[id], lo, hi);
    const auto index = [&](int x, int y, int z) {
      return base + std::size_t(x) + std::size_t(dims[0]) * (y + std::size_t(dims[1]) * z);
    };
    kept.clear();
    const bool one = lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2];
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const int cell[3] = {x, y, z};
          if (one || may_overlap(prims[id], grid_cell_box(bounds, dims, cell))) kept.push_back(index(x, y, z));
        }
    if (kept.empty())
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) kept.push_back(index(x, y, z));
    for (const std::size_t c : kept) fn(c);
  };
  const std::size_t ncells = std::size_t(dims[0]) * dims[1] * dims[2];
  for (std::size_t c = base; c < base + ncells; ++c) cells[c] = GridCell{0, 0};
  for (std::size_t i = 0; i < count; ++i) for_each_cell(ids[i], [&](std::size_t c) { ++cells[c].count; });
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
    for_each_cell(ids[i], [&](std::size_t c) { lists[cells[c].first + cells[c].count++] = ids[i]; });
}

// Each empty cell of the level at cells[base, base + dims product) gets its
// chessboard and city-block distances to the nearest cell that is not empty
// (records.hpp), each by the two-pass chamfer transform, exact for these
// metrics: a forward pass takes the neighbours met before a cell in
// x-fastest order, a backward pass the others; all 26 neighbours count for
// the chessboard distance, the 6 that share a face for the city-block one.
// A level with no occupied cell keeps the largest distance a field holds.
void set_empty_distances(std::vector<GridCell>& cells, std::size_t base, const int dims[3]) {
  const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  constexpr std::uint32_t far = kGridDistanceMax;
  std::vector<std::uint32_t> chess(static_cast<std::size_t>(nx * ny * nz)), city(chess.size());
  for (std::size_t i = 0; i < chess.size(); ++i) chess[i] = city[i] = cells[base + i].count != 0 ? 0 : far;
  const auto pass = [&](int dir) {
    const std::int64_t z0 = dir > 0 ? 0 : nz - 1, y0 = dir > 0 ? 0 : ny - 1, x0 = dir > 0 ? 0 : nx - 1;
    for (std::int64_t z = z0; z >= 0 && z < nz; z += dir)
      for (std::int64_t y = y0; y >= 0 && y < ny; y += dir)
        for (std::int64_t x = x0; x >= 0 && x < nx; x += dir) {
          const auto at = static_cast<std::size_t>(x + nx * (y + ny * z));
          if (chess[at] == 0) continue;
          // The 13 neighbours that come before (dir > 0) or after (dir < 0) this cell.
          for (int dz = 0; dz <= 1; ++dz)
            for (int dy = dz ? -1 : 0; dy <= 1; ++dy)
              for (int dx = dz || dy ? -1 : 1; dx <= 1; ++dx) {
                const std::int64_t qx = x - dir * dx, qy = y - dir * dy, qz = z - dir * dz;
                if (qx < 0 || qx >= nx || qy < 0 || qy >= ny || qz < 0 || qz >= nz) continue;
                const auto q = static_cast<std::size_t>(qx + nx * (qy + ny * qz));
                chess[at] = std::min(chess[at], chess[q] + 1);
                if (std::abs(dx) + std::abs(dy) + dz == 1) city[at] = std::min(city[at], city[q] + 1);
              }
        }
  };
  pass(1);
  pass(-1);
  for (std::size_t i = 0; i < chess.size(); ++i)
    if (cells[base + i].count == 0) cells[base + i].first = std::min(chess[i], far) | std::min(city[i], far) << 16;
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

GridBuild build_grid(std::span<const PrimRecord> prims, std::span<const Box3f> prim_bounds, const Box3f& bounds,
                     float density) {
  GridBuild g;
  choose_dims(bounds, prim_bounds.size(), density, kMaxDim, g.dims);
  const std::size_t ntop = std::size_t(g.dims[0]) * g.dims[1] * g.dims[2];
  std::vector<std::uint32_t> all(prim_bounds.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  std::vector<GridCell> top(ntop);
  std::vector<std::uint32_t> top_lists;
  fill_level(prims, prim_bounds, all.data(), all.size(), bounds, g.dims, 0, top, top_lists);
  std::vector<std::uint32_t>().swap(all);

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
    fill_level(prims, prim_bounds, top_lists.data() + tc.first, tc.count, box, sub, base, g.cells, g.lists);
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
  set_empty_distances(g.cells, 0, g.dims);
  for (std::size_t c = 0; c < ntop; ++c) {
    if (!(g.cells[c].count & kGridSubgridFlag)) continue;
    int sub[3];
    decode_subgrid(g.cells[c].count, sub);
    set_empty_distances(g.cells, g.cells[c].first, sub);
  }
  return g;
}

}  // namespace tracer
