// tracer_bench: single-thread throughput of the paged tracer on the paper's
// scenes at 512x512, measured side by side in one run:
//  - "embree workload": one eye ray per pixel centre plus one shadow ray per
//    light from each hit (the workload of the Embree reference figures), for
//    vmpray and, when built with Embree, for Embree's rtcIntersect1/rtcOccluded1,
//    with both sides' hit and occlusion counts, and a warning when the scene
//    has primitives other than triangles (Embree's side leaves them out);
//  - the full Whitted render (primary + shadow + reflected + refracted);
//  - the same render at page sizes 256 and 65536 (paging granularity cost),
//    interleaved with the 1 KB one, checked same image;
//  - the paging overhead: the 1 KB paged render against direct access, the
//    database as one contiguous array with 64 KB pages (page() is then one add,
//    with no table, and is called least often), same rays, checked same image.
//  - the paper's uniform grid on the same rays, primary + shadow and Whitted,
//    its runs alternating with the BVH's, and the grid's time over the BVH's
//    (checked same image); `--grid` runs this comparison alone.
// Then the time to triangulate concave polygons (toothed wheels) of growing
// size.
// Times are thread CPU seconds, so other processes on the machine skew them less.
#include <time.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <utility>
#include <string>
#include <tuple>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "tracer/database.hpp"
#include "tracer/generators.hpp"
#include "tracer/geometry.hpp"
#include "tracer/render.hpp"

#ifdef VMPRAY_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Workload {
  std::uint64_t rays = 0;
  double seconds = 0;
  std::uint64_t hits = 0;      // primary + shadow workload: eye rays that hit
  std::uint64_t shadowed = 0;  // and shadow rays found occluded
  double mrays() const { return seconds > 0 ? double(rays) / seconds * 1e-6 : 0.0; }
};

constexpr int kRepeats = 5;  // runs of each timed workload; the fastest counts

Workload faster(const Workload& a, const Workload& b) {
  return a.seconds > 0 && a.seconds <= b.seconds ? a : b;
}

// Eye ray per pixel centre, then a shadow ray to every light from each hit.
Workload vmpray_primary_shadow(const tracer::Database& db) {
  tracer::InMemoryPageSource pages(db);
  tracer::Tracer tracer(db.header, pages);
  const tracer::CameraModel camera(db.header.camera);
  tracer::RayStats stats;
  Workload w;
  const double t0 = cpu_seconds();
  for (int y = 0; y < db.header.camera.height; ++y)
    for (int x = 0; x < db.header.camera.width; ++x) {
      const tracer::Ray ray = camera.ray_through(x, y);
      ++w.rays;
      const auto hit = tracer.closest_hit(ray, camera.hither(), 1e30f, stats);
      if (!hit) continue;
      ++w.hits;
      const tracer::Vec3f p = ray.origin + ray.dir * hit->t;
      for (const auto& light : db.header.lights) {
        const tracer::Vec3f d = light.position - p;
        ++w.rays;
        w.shadowed += tracer.occluded({p, d}, db.header.epsilon, 1.0f, stats) ? 1 : 0;
      }
    }
  w.seconds = cpu_seconds() - t0;
  return w;
}

// Direct access: every page of the database copied into one contiguous array,
// so a page is found by address arithmetic alone.
class ContiguousPageSource final : public tracer::PageSource {
 public:
  explicit ContiguousPageSource(const tracer::Database& db)
      : shift_(db.header.page_shift), bytes_(db.header.bytes()) {
    for (std::size_t i = 0; i < db.pages.size(); ++i)
      std::memcpy(bytes_.data() + (i << shift_), db.pages[i].data(), db.header.page_size);
  }
  const std::byte* page(tracer::PageId id) override {
    return bytes_.data() + (std::size_t{id} << shift_);
  }

 private:
  std::uint32_t shift_;
  std::vector<std::byte> bytes_;
};

Workload whitted_from(const tracer::Database& db, tracer::PageSource& pages,
                      std::uint64_t* page_calls, std::vector<tracer::Color>* image) {
  tracer::RayStats stats;
  const double t0 = cpu_seconds();
  std::vector<tracer::Color> out = tracer::render_frame(db.header, pages, {}, stats);
  const double seconds = cpu_seconds() - t0;
  if (page_calls) *page_calls = stats.page_calls;
  if (image) *image = std::move(out);
  return {stats.rays(), seconds};
}

Workload vmpray_whitted(const tracer::Database& db, std::uint64_t* page_calls = nullptr,
                        std::vector<tracer::Color>* image = nullptr) {
  tracer::InMemoryPageSource pages(db);
  return whitted_from(db, pages, page_calls, image);
}

#ifdef VMPRAY_HAVE_EMBREE
// Primitives of the database that are not triangles: Embree's side leaves
// them out, so its rays are not the same work as vmpray's when any exist.
std::uint64_t non_triangles(const tracer::Database& db) {
  const auto& sec = db.header.section(tracer::Section::prims);
  std::uint64_t count = 0;
  for (std::uint32_t i = 0; i < sec.record_count; ++i) {
    const std::size_t byte = std::size_t{i} * sizeof(tracer::PrimRecord);
    tracer::PrimRecord p;
    std::memcpy(&p, db.pages[sec.first_page + byte / db.header.page_size].data() + byte % db.header.page_size,
                sizeof p);
    count += p.kind != tracer::PrimKind::flat_triangle && p.kind != tracer::PrimKind::smooth_triangle ? 1 : 0;
  }
  return count;
}

// The database's triangles (read back from the packed pages) in an Embree scene.
Workload embree_primary_shadow(const tracer::Database& db) {
  const auto& sec = db.header.section(tracer::Section::prims);
  std::vector<float> verts;
  std::vector<unsigned> index;
  for (std::uint32_t i = 0; i < sec.record_count; ++i) {
    const std::size_t byte = std::size_t{i} * sizeof(tracer::PrimRecord);
    tracer::PrimRecord p;
    std::memcpy(&p, db.pages[sec.first_page + byte / db.header.page_size].data() +
                        byte % db.header.page_size, sizeof p);
    if (p.kind != tracer::PrimKind::flat_triangle && p.kind != tracer::PrimKind::smooth_triangle)
      continue;
    for (const tracer::Vec3f& v : {p.p0, p.p0 + p.p1, p.p0 + p.p2}) {
      index.push_back(static_cast<unsigned>(verts.size() / 3));
      verts.insert(verts.end(), {v.x, v.y, v.z});
    }
  }
  RTCDevice device = rtcNewDevice("threads=1");
  RTCScene scene = rtcNewScene(device);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 12, verts.size() / 3));
  std::copy(verts.begin(), verts.end(), vb);
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 12, index.size() / 3));
  std::copy(index.begin(), index.end(), ib);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  const tracer::CameraModel camera(db.header.camera);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  Workload w;
  const double t0 = cpu_seconds();
  for (int y = 0; y < db.header.camera.height; ++y)
    for (int x = 0; x < db.header.camera.width; ++x) {
      const tracer::Ray ray = camera.ray_through(x, y);
      RTCRayHit rh{};
      rh.ray = {ray.origin.x, ray.origin.y, ray.origin.z, camera.hither(),
                ray.dir.x, ray.dir.y, ray.dir.z, 0.0f, 1e30f, 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      ++w.rays;
      rtcIntersect1(scene, &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      ++w.hits;
      const tracer::Vec3f p = ray.origin + ray.dir * rh.ray.tfar;
      for (const auto& light : db.header.lights) {
        const tracer::Vec3f d = light.position - p;
        RTCRay s{p.x, p.y, p.z, db.header.epsilon, d.x, d.y, d.z, 0.0f, 1.0f, 0xffffffffu, 0, 0};
        ++w.rays;
        rtcOccluded1(scene, &ctx, &s);
        w.shadowed += s.tfar < 0.0f ? 1 : 0;  // Embree marks an occluded ray with tfar = -inf
      }
    }
  w.seconds = cpu_seconds() - t0;
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return w;
}
#endif

// The grid against the BVH on the same rays: each workload's fastest of
// kRepeats runs, the two structures alternating.
float grid_density = tracer::BuildOptions{}.grid_density;  // --density D

void bench_grid(const tracer::Scene& scene, const tracer::Database& bvh) {
  const tracer::Database grid =
      build_database(scene, {.accel = tracer::Accel::grid, .page_size = 1024, .grid_density = grid_density});
  const int* dims = grid.header.grid_dims;
  std::printf(
      "  grid %dx%dx%d top cells, %llu subgrids, %llu cells, %.2f references per primitive, build %.3f s, "
      "%u pages (%.0f KB)\n",
      dims[0], dims[1], dims[2], static_cast<unsigned long long>(grid.stats.grid_subgrids),
      static_cast<unsigned long long>(grid.stats.grid_cells),
      double(grid.stats.grid_references) / double(grid.header.primitive_count), grid.stats.accel_seconds,
      grid.header.page_count, grid.header.bytes() / 1024.0);
  Workload bvh_ps, grid_ps, bvh_w, grid_w;
  std::vector<tracer::Color> bvh_image, grid_image;
  for (int rep = 0; rep < kRepeats; ++rep) {
    bvh_ps = faster(bvh_ps, vmpray_primary_shadow(bvh));
    grid_ps = faster(grid_ps, vmpray_primary_shadow(grid));
    bvh_w = faster(bvh_w, vmpray_whitted(bvh, nullptr, &bvh_image));
    grid_w = faster(grid_w, vmpray_whitted(grid, nullptr, &grid_image));
  }
  std::printf("  grid vs BVH     primary+shadow grid %6.2f  BVH %6.2f Mrays/s  time grid/BVH %.2f\n", grid_ps.mrays(),
              bvh_ps.mrays(), grid_ps.seconds / bvh_ps.seconds);
  std::printf("                  whitted        grid %6.2f  BVH %6.2f Mrays/s  time grid/BVH %.2f  %s\n",
              grid_w.mrays(), bvh_w.mrays(), grid_w.seconds / bvh_w.seconds,
              grid_image == bvh_image ? "same image" : "IMAGES DIFFER");
  for (const tracer::Database* db : {&grid, &bvh}) {
    tracer::InMemoryPageSource pages(*db);
    tracer::RayStats stats;
    tracer::render_frame(db->header, pages, {}, stats);
    const double rays = double(stats.rays());
    std::printf("                  %s per ray: %.1f %s, %.1f primitive tests, %.1f page() calls\n",
                db == &grid ? "grid" : "BVH ", double(stats.box_tests) / rays, db == &grid ? "cells" : "boxes",
                double(stats.prim_tests) / rays, double(stats.page_calls) / rays);
  }
}

void bench_scene(const std::string& spec, bool grid_only) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = scene.camera.height = 512;
  const tracer::Database db = build_database(scene, {.page_size = 1024});
  std::printf("%-9s %8llu prims  BVH build %.3f s  %6u pages (%.0f KB)\n", spec.c_str(),
              static_cast<unsigned long long>(db.header.primitive_count), db.stats.accel_seconds,
              db.header.page_count, db.header.bytes() / 1024.0);
  if (grid_only) return bench_grid(scene, db);
  // Alternate the two tracers and keep each one's fastest run, so a burst of
  // load from other processes skews one side less.
  Workload ours;
#ifdef VMPRAY_HAVE_EMBREE
  Workload ref;
#endif
  for (int rep = 0; rep < kRepeats; ++rep) {
    ours = faster(ours, vmpray_primary_shadow(db));
#ifdef VMPRAY_HAVE_EMBREE
    ref = faster(ref, embree_primary_shadow(db));
#endif
  }
  std::printf("  primary+shadow  vmpray %6.2f Mrays/s (%llu rays)", ours.mrays(),
              static_cast<unsigned long long>(ours.rays));
#ifdef VMPRAY_HAVE_EMBREE
  std::printf("  embree %6.2f Mrays/s  ratio vmpray/embree %.2f", ref.mrays(), ours.mrays() / ref.mrays());
#endif
  std::printf("\n");
#ifdef VMPRAY_HAVE_EMBREE
  // Like with like: the same primitives, and the same rays finding the same
  // answers (hit and occlusion counts; a few silhouette rays may differ in
  // the last bit of two different intersection codes).
  const std::uint64_t left_out = non_triangles(db);
  const double apart = double(std::max(ours.rays, ref.rays) - std::min(ours.rays, ref.rays));
  std::printf("                  eye rays hitting vmpray %llu embree %llu, shadow rays occluded vmpray %llu embree %llu"
              "  rays traced differ by %.0f (%.3f%%)\n",
              static_cast<unsigned long long>(ours.hits), static_cast<unsigned long long>(ref.hits),
              static_cast<unsigned long long>(ours.shadowed), static_cast<unsigned long long>(ref.shadowed), apart,
              100.0 * apart / double(ours.rays));
  if (left_out)
    std::printf("                  NOT COMPARABLE: %llu primitives are not triangles, and Embree's scene leaves them out\n",
                static_cast<unsigned long long>(left_out));
#endif
  const tracer::Database big = build_database(scene, {.page_size = 65536});
  const tracer::Database small = build_database(scene, {.page_size = 256});
  ContiguousPageSource direct(big);
  std::uint64_t calls = 0, calls_small = 0, calls_big = 0;
  std::vector<tracer::Color> paged_image, direct_image, small_image, big_image;
  // Every page size and the direct access run in turn, each keeping its
  // fastest of kRepeats runs: the same statistic on every side of a ratio.
  Workload whitted, d, at_small, at_big;
  for (int rep = 0; rep < kRepeats; ++rep) {
    whitted = faster(whitted, vmpray_whitted(db, &calls, &paged_image));
    at_small = faster(at_small, vmpray_whitted(small, &calls_small, &small_image));
    at_big = faster(at_big, vmpray_whitted(big, &calls_big, &big_image));
    d = faster(d, whitted_from(big, direct, nullptr, &direct_image));
  }
  std::printf("  whitted @ 1024  vmpray %6.2f Mrays/s (%llu rays, %.2f s, %.2f page() calls/ray)\n",
              whitted.mrays(), static_cast<unsigned long long>(whitted.rays), whitted.seconds,
              double(calls) / double(whitted.rays));
  // 64 KB pages: page() is almost never called, the closest to unpaged access.
  for (const auto& [ps, w, c, image] : {std::tuple{256u, at_small, calls_small, &small_image},
                                        std::tuple{65536u, at_big, calls_big, &big_image}})
    std::printf("  whitted @%5u  vmpray %6.2f Mrays/s (%.2f page() calls/ray)  time ratio vs 1024: %.3f  %s\n", ps,
                w.mrays(), double(c) / double(w.rays), w.seconds / whitted.seconds,
                *image == paged_image ? "same image" : "IMAGES DIFFER");
  std::printf("  whitted direct  vmpray %6.2f Mrays/s  paging overhead (1 KB paged / direct time) %.3f  %s\n",
              d.mrays(), whitted.seconds / d.seconds,
              direct_image == paged_image ? "same image" : "IMAGES DIFFER");
  bench_grid(scene, db);
}

// A wheel of `teeth` trapezoid teeth (radii 1 and 0.8), counter-clockwise
// from a tooth's tip: 4 * teeth vertices, one in four a reflex corner.
std::vector<tracer::Vec3d> toothed_wheel(int teeth) {
  std::vector<tracer::Vec3d> v;
  const double step = 2 * std::numbers::pi / teeth;
  for (int t = 0; t < teeth; ++t)
    for (const auto& [radius, at] : {std::pair{1.0, 0.0}, {1.0, 0.3}, {0.8, 0.5}, {0.8, 0.8}}) {
      const double a = (t + at) * step;
      v.push_back({radius * std::cos(a), radius * std::sin(a), 0});
    }
  return v;
}

// Concave polygons are cut by ear clipping; the time per vertex should not
// grow with the polygon.
void bench_triangulation() {
  std::printf("concave polygon triangulation (toothed wheels):\n");
  for (int teeth : {500, 2000, 8000}) {
    const std::vector<tracer::Vec3d> v = toothed_wheel(teeth);
    double best = 1e30;
    std::size_t triangles = 0;
    for (int rep = 0; rep < kRepeats; ++rep) {
      const double t0 = cpu_seconds();
      triangles = tracer::triangulate_polygon(v).size();
      best = std::min(best, cpu_seconds() - t0);
    }
    std::printf("  %6zu vertices  %8.3f ms  %6.1f ns per vertex  %s\n", v.size(), best * 1e3,
                best * 1e9 / double(v.size()), triangles == v.size() - 2 ? "n - 2 triangles" : "WRONG COUNT");
  }
}

}  // namespace

const char* const usage =
    "usage: tracer_bench [--grid] [--density CELLS_PER_PRIMITIVE] [SCENE...]\n"
    "  (default scenes teapot mountain rings4 tetra9; density above 0, at most 64)\n";

int bench_tracer(const std::vector<std::string>& args) {
  std::vector<std::string> scenes;
  bool grid_only = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--grid") {
      grid_only = true;
    } else if (args[i] == "--density") {
      if (i + 1 == args.size()) throw bench::BadArgument{"--density needs a value"};
      const std::string& v = args[++i];
      float d = 0;
      const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), d);
      if (ec != std::errc() || end != v.data() + v.size() || !(d > 0 && d <= 64))
        throw bench::BadArgument{"--density: expected a number above 0, at most 64, got '" + v + "'"};
      grid_density = d;
    } else if (args[i].starts_with("-")) {
      throw bench::BadArgument{"unknown option '" + args[i] + "'"};
    } else {
      scenes.push_back(args[i]);
    }
  }
  if (scenes.empty()) scenes = {"teapot", "mountain", "rings4", "tetra9"};
  for (const auto& s : scenes) tracer::generate_scene(s);  // an unknown scene fails before any work
  for (const auto& s : scenes) bench_scene(s, grid_only);
  if (!grid_only) bench_triangulation();
  return 0;
}

int main(int argc, char** argv) { return bench::run_main("tracer_bench", usage, argc, argv, bench_tracer); }
