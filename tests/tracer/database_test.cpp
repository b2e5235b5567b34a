// Packing invariants of the paged database and page-size validation.
#include "tracer/database.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "test_scenes.hpp"
#include "tracer/bvh.hpp"
#include "tracer/generators.hpp"

namespace tracer {
namespace {

template <class T>
T record(const Database& db, Section s, std::uint64_t i) {
  const SectionLayout& l = db.header.section(s);
  const std::uint64_t byte = i * l.record_size;
  const std::uint64_t offset = byte % db.header.page_size;
  EXPECT_LE(offset + l.record_size, db.header.page_size) << "record straddles a page";
  T out;
  std::memcpy(&out, db.pages.at(l.first_page + byte / db.header.page_size).data() + offset,
              sizeof out);
  return out;
}

// Each empty cell of the grid level of `dims` cells from record `base`
// holds its chessboard and city-block distances to the nearest occupied
// cell of the level (records.hpp), by brute force.
void expect_empty_distances(const Database& db, std::uint64_t base, const int dims[3]) {
  const auto at = [&](int x, int y, int z) {
    return record<GridCell>(db, Section::grid_cells, base + x + std::uint64_t(dims[0]) * (y + std::uint64_t(dims[1]) * z));
  };
  for (int z = 0; z < dims[2]; ++z)
    for (int y = 0; y < dims[1]; ++y)
      for (int x = 0; x < dims[0]; ++x) {
        const GridCell c = at(x, y, z);
        if (c.count != 0) continue;
        std::uint32_t chess = kGridDistanceMax, city = kGridDistanceMax;
        for (int qz = 0; qz < dims[2]; ++qz)
          for (int qy = 0; qy < dims[1]; ++qy)
            for (int qx = 0; qx < dims[0]; ++qx) {
              if (at(qx, qy, qz).count == 0) continue;
              const int d[3] = {std::abs(qx - x), std::abs(qy - y), std::abs(qz - z)};
              chess = std::min(chess, std::uint32_t(std::max({d[0], d[1], d[2]})));
              city = std::min(city, std::uint32_t(d[0] + d[1] + d[2]));
            }
        ASSERT_EQ(c.first & 0xffff, chess) << "empty cell " << x << "," << y << "," << z << " at " << base;
        ASSERT_EQ(c.first >> 16, city) << "empty cell " << x << "," << y << "," << z << " at " << base;
      }
}

void expect_consistent(const Database& db) {
  const DatabaseHeader& h = db.header;
  ASSERT_EQ(db.pages.size(), h.page_count);
  for (const auto& p : db.pages) ASSERT_EQ(p.size(), h.page_size);
  const auto& prims = h.section(Section::prims);
  const auto& mats = h.section(Section::materials);
  const auto& normals = h.section(Section::normals);
  for (std::uint32_t i = 0; i < prims.record_count; ++i) {
    const auto p = record<PrimRecord>(db, Section::prims, i);
    EXPECT_LT(p.material, mats.record_count);
    if (p.kind == PrimKind::smooth_triangle) {
      EXPECT_LT(p.aux, normals.record_count);
    }
  }
  if (h.accel == Accel::bvh) {
    const auto& nodes = h.section(Section::bvh_nodes);
    for (std::uint32_t i = 0; i < nodes.record_count; ++i) {
      const auto n = record<BvhNode>(db, Section::bvh_nodes, i);
      for (int c = 0; c < 4; ++c) {
        if (n.lo[0][c] > n.hi[0][c]) continue;  // unused lane
        if (n.count[c] == 0) {
          EXPECT_LT(n.child[c], nodes.record_count);
        } else {
          EXPECT_LE(std::uint64_t{n.child[c]} + n.count[c], prims.record_count);
        }
      }
    }
  } else {
    const auto& cells = h.section(Section::grid_cells);
    const auto& lists = h.section(Section::grid_lists);
    // The top cells, then each subgrid's cells once, right after the cells before it.
    const std::uint32_t top = std::uint32_t(h.grid_dims[0] * h.grid_dims[1] * h.grid_dims[2]);
    std::uint64_t next_subgrid = top;
    for (std::uint32_t i = 0; i < cells.record_count; ++i) {
      const auto c = record<GridCell>(db, Section::grid_cells, i);
      if (c.count & kGridSubgridFlag) {
        ASSERT_LT(i, top) << "a subgrid inside a subgrid";
        int dims[3];
        decode_subgrid(c.count, dims);
        EXPECT_EQ(c.first, next_subgrid);
        expect_empty_distances(db, c.first, dims);
        next_subgrid += std::uint64_t(dims[0]) * dims[1] * dims[2];
        continue;
      }
      if (c.count == 0) continue;  // its `first` is a distance, checked by level
      EXPECT_LE(std::uint64_t{c.first} + c.count, lists.record_count);
      for (std::uint32_t k = 1; k < c.count; ++k)
        EXPECT_LT(record<std::uint32_t>(db, Section::grid_lists, c.first + k - 1),
                  record<std::uint32_t>(db, Section::grid_lists, c.first + k));
    }
    EXPECT_EQ(next_subgrid, cells.record_count);
    expect_empty_distances(db, 0, h.grid_dims);
    for (std::uint32_t i = 0; i < lists.record_count; ++i)
      EXPECT_LT(record<std::uint32_t>(db, Section::grid_lists, i), prims.record_count);
  }
}

TEST(Database, PackingKeepsRecordsInPagesAndReferencesResolve) {
  const Scene scene = testing::showcase_scene(8);
  for (Accel accel : {Accel::bvh, Accel::grid})
    for (std::uint32_t page_size : {256u, 1024u, 65536u}) {
      SCOPED_TRACE(page_size);
      expect_consistent(build_database(scene, {.accel = accel, .page_size = page_size}));
    }
  expect_consistent(build_database(testing::random_scene(3, 300, 20), {.accel = Accel::grid}));
}

TEST(Database, SectionsStartOnPageBoundariesInOrder) {
  const Database db = build_database(testing::random_scene(5, 200, 10), {.page_size = 256});
  std::uint32_t pages = 0;
  for (const SectionLayout& s : db.header.sections)
    pages += static_cast<std::uint32_t>((std::uint64_t{s.record_count} * s.record_size + 255) / 256);
  EXPECT_EQ(pages, db.header.page_count);  // no page is shared by two sections
}

TEST(Database, PackingIsDeterministic) {
  const Scene scene = testing::random_scene(9, 300, 30);
  const Database a = build_database(scene), b = build_database(scene);
  EXPECT_EQ(a.pages, b.pages);
}

// tetra:8 has 65536 triangles: the BVH root is binned in chunks and its
// subtrees may be built on threads of their own.
TEST(Database, PagesAreTheSameOnAnyThreadCount) {
  const Scene scene = generate_tetra(8);
  for (const auto& [accel, layout] :
       {std::pair{Accel::bvh, BvhLayout::treelet}, std::pair{Accel::bvh, BvhLayout::depth_first},
        std::pair{Accel::grid, BvhLayout::treelet}}) {
    const Database one = build_database(scene, {.accel = accel, .bvh_layout = layout});
    ASSERT_GE(one.header.primitive_count, 65536u);
    for (unsigned threads : {2u, 3u, 8u}) {
      const Database many = build_database(scene, {.accel = accel, .bvh_layout = layout, .threads = threads});
      EXPECT_TRUE(one.pages == many.pages) << threads << " threads, accel " << int(accel) << ", layout " << int(layout);
      EXPECT_EQ(one.header.page_count, many.header.page_count);
      EXPECT_EQ(one.header.bvh_depth, many.header.bvh_depth);
    }
  }
}

// The build flattens objects in chunks of 4096 on its threads and puts the
// primitives in leaf order in pieces of 65 536: smooth patches (whose
// triangles index their normals), quads cut in two, spheres and cones, in
// chunks and pieces that end in the middle of each kind, joined in the
// one-thread order with the normals renumbered.
Vec3d patch_normal(std::uint32_t object) { return {(object % 97) * 0.01, (object % 89) * 0.01, 1}; }

TEST(Database, FlatteningInChunksOnThreadsGivesTheSamePages) {
  Scene scene = testing::showcase_scene(8);
  const auto first = static_cast<std::uint32_t>(scene.objects.size());  // the objects added here
  for (int i = 0; i < 60000; ++i) {  // 75 000 primitives
    const double x = (i % 250) * 0.02 - 2.5, y = (i / 250) * 0.02 - 2.5;
    switch (i % 4) {
      case 0: {  // its normals its own, so that each triangle's can be traced back to it
        const Vec3d n = patch_normal(static_cast<std::uint32_t>(scene.objects.size()));
        scene.objects.push_back(
            {Patch{{{x, y, 0.1}, {x + 0.015, y, 0.1}, {x + 0.015, y + 0.015, 0.12}, {x, y + 0.015, 0.1}}, {n, n, n, n}},
             1});
        break;
      }
      case 1: scene.objects.push_back({Polygon{{{x, y, 0.2}, {x + 0.015, y, 0.2}, {x, y + 0.015, 0.21}}}, 0}); break;
      case 2: scene.objects.push_back({Sphere{{x, y, 0.3}, 0.005}, 2}); break;
      default: scene.objects.push_back({Cone{{x, y, 0.4}, 0.005, {x, y, 0.45}, 0.0}, 3}); break;
    }
  }
  for (const Accel accel : {Accel::bvh, Accel::grid}) {
    const Database one = build_database(scene, {.accel = accel});
    // Every smooth triangle's normals are its own patch's.
    std::uint32_t smooth = 0;
    for (std::uint32_t i = 0; i < one.header.section(Section::prims).record_count; ++i) {
      const auto p = record<PrimRecord>(one, Section::prims, i);
      if (p.kind != PrimKind::smooth_triangle || p.object < first) continue;
      ++smooth;
      const Vec3f want = static_cast<Vec3f>(normalize(patch_normal(p.object)));
      const auto n = record<NormalRecord>(one, Section::normals, p.aux);
      ASSERT_TRUE(n.n0 == want && n.n1 == want && n.n2 == want) << "primitive " << i << " of object " << p.object;
    }
    EXPECT_EQ(smooth, 2u * 15000);
    for (unsigned threads : {2u, 3u}) {
      const Database many = build_database(scene, {.accel = accel, .threads = threads});
      EXPECT_TRUE(one.pages == many.pages) << threads << " threads, accel " << int(accel);
      EXPECT_EQ(one.header.primitive_count, many.header.primitive_count);
    }
  }
}

// A scene the build consumes (build_database(Scene&&), as the command line
// builds) gives the pages and counts of the scene kept, on any thread count;
// it keeps its camera, lights and materials, and its objects are gone. The
// scene has polygons that make fewer triangles than their vertices allow
// (collinear first corners) and a concave one, patches, spheres and cones,
// in more chunks than the build gives memory back after.
TEST(Database, AConsumedSceneGivesThePagesOfTheSceneKept) {
  Scene scene = testing::showcase_scene(8);
  for (int i = 0; i < 80000; ++i) {
    const double x = (i % 300) * 0.02 - 3, y = (i / 300) * 0.02 - 3;
    switch (i % 5) {
      case 0: scene.objects.push_back({Polygon{{{x, y, 0}, {x + 0.01, y, 0}, {x + 0.02, y, 0}, {x, y + 0.01, 0}}}, 0}); break;
      case 1:
        scene.objects.push_back(
            {Polygon{{{x, y, 0.1}, {x + 0.02, y, 0.1}, {x + 0.01, y + 0.005, 0.1}, {x + 0.01, y + 0.02, 0.1}}}, 1});
        break;
      case 2: {
        const Vec3d n{0.1, 0, 1};
        scene.objects.push_back({Patch{{{x, y, 0.2}, {x + 0.015, y, 0.2}, {x, y + 0.015, 0.21}}, {n, n, n}}, 2});
        break;
      }
      case 3: scene.objects.push_back({Sphere{{x, y, 0.3}, 0.005}, 3}); break;
      default: scene.objects.push_back({Cone{{x, y, 0.4}, 0.005, {x, y, 0.45}, 0.002}, 0}); break;
    }
  }
  for (const Accel accel : {Accel::bvh, Accel::grid}) {
    const Database kept = build_database(scene, {.accel = accel});
    for (unsigned threads : {1u, 2u, 3u}) {
      SCOPED_TRACE(std::to_string(threads) + " threads, accel " + std::to_string(int(accel)));
      Scene consumed = scene;
      const Database db = build_database(std::move(consumed), {.accel = accel, .threads = threads});
      EXPECT_TRUE(db.pages == kept.pages);
      EXPECT_EQ(db.header.primitive_count, kept.header.primitive_count);
      EXPECT_EQ(db.header.polygon_count, kept.header.polygon_count);
      EXPECT_EQ(db.header.object_count, scene.objects.size());
      EXPECT_TRUE(consumed.objects.empty());  // NOLINT(bugprone-use-after-move): what the build leaves
      EXPECT_EQ(consumed.materials.size(), scene.materials.size());
      EXPECT_EQ(consumed.lights.size(), scene.lights.size());
      EXPECT_EQ(consumed.camera.width, scene.camera.width);
    }
  }
}

// Triangles much longer than the rest are split among several leaves, so
// the leaves list some primitives more than once. Every leaf's records are
// primitives whose boxes meet the leaf's box, every primitive is in a
// leaf, and a split one is in several: the records were put in leaf order
// right, copies included. The scene is large enough for the binary tree
// to span several blocks of nodes (the build's Segment).
TEST(Database, EveryLeafHoldsRecordsOfItsOwnPrimitives) {
  Scene scene = testing::random_scene(7, 200000, 40);
  const std::size_t long_ones = scene.objects.size();
  for (int i = 0; i < 30; ++i) {
    const double y = -1 + i * 0.07;
    scene.objects.push_back({Polygon{{{-1, y, -1}, {1, y + 0.01, 1}, {1, y + 0.02, -1}}}, 0});
  }
  for (const unsigned threads : {1u, 2u}) {
    const Database db = build_database(scene, {.threads = threads});
    const auto& nodes = db.header.section(Section::bvh_nodes);
    std::vector<int> leaves_of(scene.objects.size(), 0);
    std::uint64_t entries = 0;
    for (std::uint32_t i = 0; i < nodes.record_count; ++i) {
      const auto n = record<BvhNode>(db, Section::bvh_nodes, i);
      for (int lane = 0; lane < 4; ++lane) {
        if (n.count[lane] == 0) continue;  // inner or unused
        const Box3f box = lane_box(n, lane);
        for (std::uint32_t k = n.child[lane]; k < n.child[lane] + n.count[lane]; ++k) {
          const auto p = record<PrimRecord>(db, Section::prims, k);
          ASSERT_LT(p.object, scene.objects.size());
          ++leaves_of[p.object];
          ++entries;
          Box3f prim;
          if (p.kind == PrimKind::sphere) {
            const float r = std::fabs(p.p1.x);
            prim = {p.p0 - Vec3f{r, r, r}, p.p0 + Vec3f{r, r, r}};
            EXPECT_EQ(p.p0, static_cast<Vec3f>(std::get<Sphere>(scene.objects[p.object].shape).center));
          } else {
            for (const Vec3f v : {p.p0, p.p0 + p.p1, p.p0 + p.p2}) prim.extend(v);
            EXPECT_EQ(p.p0, static_cast<Vec3f>(std::get<Polygon>(scene.objects[p.object].shape).vertices[0]));
          }
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(prim.lo[a], box.hi[a] + 1e-4f) << "object " << p.object << " in a leaf it does not meet";
            EXPECT_GE(prim.hi[a], box.lo[a] - 1e-4f) << "object " << p.object << " in a leaf it does not meet";
          }
        }
      }
    }
    EXPECT_EQ(entries, db.header.section(Section::prims).record_count);
    EXPECT_EQ(std::count(leaves_of.begin(), leaves_of.end(), 0), 0) << "a primitive in no leaf";
    int split = 0;
    for (std::size_t o = long_ones; o < scene.objects.size(); ++o) split += leaves_of[o] > 1;
    EXPECT_GE(split, 20) << "the long triangles were not split: nothing was listed twice";
    // A four-wide node stands for one inner binary node at least, and a
    // binary tree has more leaves than inner nodes.
    EXPECT_GT(2 * db.stats.bvh_nodes, 65536u) << "the binary tree may fit in one block of nodes";
  }
}

TEST(Database, TriangulatesPolygonsAndCountsPolygons) {
  const Database db = build_database(testing::showcase_scene(8));
  // Quad (2) + hexagon (4) + patch (1) triangles, 3 spheres, 2 cones.
  EXPECT_EQ(db.header.primitive_count, 12u);
  EXPECT_EQ(db.header.polygon_count, 3u);
  EXPECT_EQ(db.header.bytes(), std::uint64_t{db.header.page_count} * 1024);
}

TEST(Database, RejectsPageSizesThatAreNotPowersOfTwoInRange) {
  for (std::int64_t bad : {-1024ll, 0ll, 128ll, 255ll, 1000ll, 131072ll}) {
    try {
      validate_page_size(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const DatabaseError& e) {
      EXPECT_NE(std::string(e.what()).find(std::to_string(bad)), std::string::npos);
    }
  }
  for (std::int64_t good : {256ll, 512ll, 4096ll, 65536ll}) EXPECT_NO_THROW(validate_page_size(good));
  EXPECT_THROW(build_database(testing::showcase_scene(8), {.page_size = 3000}), DatabaseError);
}

}  // namespace
}  // namespace tracer
