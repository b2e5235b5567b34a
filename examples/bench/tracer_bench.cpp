// tracer_bench: one-thread throughput of the paged tracer on the paper's
// scenes at 512x512, in CPU time of the thread. Each figure is the median of
// kRepeats runs, the runs of a comparison's sides alternating; each ratio is
// of medians. Per scene it times:
//  - primary + shadow (an eye ray per pixel centre, a shadow ray per light
//    from each hit): one loop, run on vmpray's tracer and on Embree's
//    rtcIntersect1/rtcOccluded1 over the same triangles. Both first answer
//    the same rays untimed; their counts of eye rays hitting and shadow rays
//    occluded are printed side by side, and a ray they disagree on away from
//    a triangle's edge fails the bench (kEdge says why edges may differ). A
//    scene with spheres or cones is not compared, and a line says so;
//  - the Whitted render at 1 KB, 256-byte and 64 KB pages and from one
//    contiguous copy of the database, every run's image checked against the
//    first 1 KB one;
//  - the uniform grid against the BVH on the same rays (hit counts and
//    images checked equal); --grid runs this alone;
//  - with `povray` on the PATH, the 1 KB Whitted render against POV-Ray 3.7
//    tracing the same scene (pov_scene.hpp), trace time against trace time;
// then ear clipping of toothed wheels. A failed check prints one line naming
// the scene and page size, and the bench exits 1.
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "examples/bench/pov_scene.hpp"
#include "tracer/database.hpp"
#include "tracer/generators.hpp"
#include "tracer/geometry.hpp"
#include "tracer/render.hpp"

#ifdef VMPRAY_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

constexpr int kRepeats = 5;  // runs of each timed workload; the median counts

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

// One run of a workload.
struct Run {
  std::uint64_t rays = 0;
  double seconds = 0;
  std::uint64_t hits = 0;      // primary + shadow: eye rays that hit
  std::uint64_t shadowed = 0;  // and shadow rays found occluded
  std::uint64_t shadow = 0;    // Whitted: the shadow rays among `rays`
};

// The runs of one side of a comparison.
struct Series {
  std::vector<double> seconds;
  Run last;

  void add(const Run& r) {
    seconds.push_back(r.seconds);
    last = r;
  }
  double median_seconds() const { return median(seconds); }
  double mrays() const { return double(last.rays) / median_seconds() * 1e-6; }
};

bool same_image(const std::vector<tracer::Color>& a, const std::vector<tracer::Color>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(tracer::Color)) == 0;
}

// One line on stderr for a failed check; the bench then exits 1.
void report_failure(const std::string& scene, const std::string& what) {
  std::fprintf(stderr, "tracer_bench: %s: %s\n", scene.c_str(), what.c_str());
}

// ---- primary + shadow, the same loop for both tracers ----

// vmpray's tracer behind the two queries the loop makes.
class VmprayQueries {
 public:
  explicit VmprayQueries(const tracer::Database& db) : pages_(db), tracer_(db.header, pages_) {}
  std::optional<tracer::TriangleHit> closest(const tracer::Ray& ray, float t_min, float t_max) {
    const auto hit = tracer_.closest_hit(ray, t_min, t_max, stats_);
    if (!hit) return std::nullopt;
    return tracer::TriangleHit{hit->t, hit->u, hit->v};
  }
  bool occluded(const tracer::Ray& ray, float t_min, float t_max) {
    return tracer_.occluded(ray, t_min, t_max, stats_);
  }

 private:
  tracer::InMemoryPageSource pages_;
  tracer::Tracer tracer_;
  tracer::RayStats stats_;
};

// Eye ray per pixel centre, then a shadow ray to every light from each hit.
template <class Queries>
Run primary_shadow(const tracer::DatabaseHeader& h, Queries& q) {
  const tracer::CameraModel camera(h.camera);
  Run w;
  const double t0 = cpu_seconds();
  for (int y = 0; y < h.camera.height; ++y)
    for (int x = 0; x < h.camera.width; ++x) {
      const tracer::Ray ray = camera.ray_through(x, y);
      ++w.rays;
      const auto hit = q.closest(ray, camera.hither(), 1e30f);
      if (!hit) continue;
      ++w.hits;
      const tracer::Vec3f p = ray.origin + ray.dir * hit->t;
      for (const auto& light : h.lights) {
        ++w.rays;
        w.shadowed += q.occluded({p, light.position - p}, h.epsilon, 1.0f) ? 1 : 0;
      }
    }
  w.seconds = cpu_seconds() - t0;
  return w;
}

Run vmpray_primary_shadow(const tracer::Database& db) {
  VmprayQueries q(db);
  return primary_shadow(db.header, q);
}

// ---- Whitted renders ----

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

// One Whitted render of db, from `direct` when given, else from its pages.
Run whitted(const tracer::Database& db, tracer::PageSource* direct, std::uint64_t& page_calls,
            std::vector<tracer::Color>& image) {
  tracer::InMemoryPageSource paged(db);
  tracer::PageSource& pages = direct ? *direct : paged;
  tracer::RayStats stats;
  const double t0 = cpu_seconds();
  image = tracer::render_frame(db.header, pages, {}, stats);
  const double seconds = cpu_seconds() - t0;
  page_calls = stats.page_calls;
  return {.rays = stats.rays(), .seconds = seconds, .shadow = stats.shadow};
}

// ---- Embree on the same triangles ----

#ifdef VMPRAY_HAVE_EMBREE
// The database's primitives, read back from the packed pages, each once: the
// BVH keeps a copy of a split triangle in every leaf it reaches.
std::vector<tracer::PrimRecord> distinct_prims(const tracer::Database& db) {
  const auto& sec = db.header.section(tracer::Section::prims);
  std::vector<tracer::PrimRecord> prims(sec.record_count);
  for (std::uint32_t i = 0; i < sec.record_count; ++i) {
    const std::size_t byte = std::size_t{i} * sizeof(tracer::PrimRecord);
    std::memcpy(&prims[i], db.pages[sec.first_page + byte / db.header.page_size].data() + byte % db.header.page_size,
                sizeof(tracer::PrimRecord));
  }
  const auto bytes_less = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) < 0; };
  const auto bytes_equal = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  std::sort(prims.begin(), prims.end(), bytes_less);
  prims.erase(std::unique(prims.begin(), prims.end(), bytes_equal), prims.end());
  return prims;
}

bool is_triangle(const tracer::PrimRecord& p) {
  return p.kind == tracer::PrimKind::flat_triangle || p.kind == tracer::PrimKind::smooth_triangle;
}

// One-thread Embree scene of the database's triangles, with the vertices
// v0, v0 + e1, v0 + e2 from each record (the database keeps no others).
class EmbreeQueries {
 public:
  explicit EmbreeQueries(const std::vector<tracer::PrimRecord>& prims) {
    device_ = rtcNewDevice("threads=1");
    scene_ = rtcNewScene(device_);
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * prims.size()));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, prims.size()));
    unsigned n = 0;
    for (const tracer::PrimRecord& p : prims)
      for (const tracer::Vec3f& v : {p.p0, p.p0 + p.p1, p.p0 + p.p2}) {
        vb[3 * n] = v.x;
        vb[3 * n + 1] = v.y;
        vb[3 * n + 2] = v.z;
        ib[n] = n;
        ++n;
      }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene_);
    rtcInitIntersectContext(&ctx_);
  }
  EmbreeQueries(const EmbreeQueries&) = delete;
  EmbreeQueries& operator=(const EmbreeQueries&) = delete;
  ~EmbreeQueries() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  std::optional<tracer::TriangleHit> closest(const tracer::Ray& r, float t_min, float t_max) {
    RTCRayHit rh{};
    rh.ray = {r.origin.x, r.origin.y, r.origin.z, t_min, r.dir.x, r.dir.y, r.dir.z, 0.0f, t_max, 0xffffffffu, 0, 0};
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx_, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    return tracer::TriangleHit{rh.ray.tfar, rh.hit.u, rh.hit.v};
  }
  bool occluded(const tracer::Ray& r, float t_min, float t_max) {
    RTCRay s{r.origin.x, r.origin.y, r.origin.z, t_min, r.dir.x, r.dir.y, r.dir.z, 0.0f, t_max, 0xffffffffu, 0, 0};
    rtcOccluded1(scene_, &ctx_, &s);
    return s.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
  }

 private:
  RTCDevice device_;
  RTCScene scene_;
  RTCIntersectContext ctx_;
};

// Why two correct tracers may disagree on a ray: the database keeps a
// triangle as v0 and two edges, so Embree's vertices v0 + e1, v0 + e2 are
// rounded once more, and neighbouring triangles no longer share their edges
// bit for bit; and the two intersection tests (Moeller-Trumbore here,
// Embree's own there) round differently. Both move only rays that pass
// within a few ulps of an edge. So a ray they disagree on is accepted when
// the triangle the one side found is met within kEdge of an edge (in
// barycentric coordinates); any other disagreement fails the bench. On the
// four default scenes the rays that differ (45 of 2.4 million) all
// lie within 1e-5 of an edge.
constexpr float kEdge = 1e-4f;

bool edge_ray(const std::optional<tracer::TriangleHit>& h) {
  return h && std::min({h->u, h->v, 1.0f - h->u - h->v}) < kEdge;
}

// Counts of one kind of ray, vmpray's beside Embree's.
struct HitCount {
  std::uint64_t rays = 0, ours = 0, embree = 0;
  std::uint64_t differ = 0;      // rays answered differently
  std::uint64_t off_edge = 0;    // of those, rays not explained by an edge

  void add(bool a, bool b, bool at_edge) {
    ++rays;
    ours += a ? 1 : 0;
    embree += b ? 1 : 0;
    differ += a != b ? 1 : 0;
    off_edge += a != b && !at_edge ? 1 : 0;
  }
};

struct HitCheck {
  HitCount eye, shadow;
};

// Both tracers answer the same rays: each eye ray, and each shadow ray from
// vmpray's hit point where both hit.
HitCheck compare_hits(const tracer::DatabaseHeader& h, VmprayQueries& ours, EmbreeQueries& ref) {
  const tracer::CameraModel camera(h.camera);
  HitCheck c;
  for (int y = 0; y < h.camera.height; ++y)
    for (int x = 0; x < h.camera.width; ++x) {
      const tracer::Ray ray = camera.ray_through(x, y);
      const auto a = ours.closest(ray, camera.hither(), 1e30f);
      const auto b = ref.closest(ray, camera.hither(), 1e30f);
      c.eye.add(a.has_value(), b.has_value(), edge_ray(a ? a : b));
      if (!a || !b) continue;
      const tracer::Vec3f p = ray.origin + ray.dir * a->t;
      for (const auto& light : h.lights) {
        const tracer::Ray s{p, light.position - p};
        const bool sa = ours.occluded(s, h.epsilon, 1.0f), sb = ref.occluded(s, h.epsilon, 1.0f);
        c.shadow.add(sa, sb, sa != sb && edge_ray(sa ? ours.closest(s, h.epsilon, 1.0f)
                                                     : ref.closest(s, h.epsilon, 1.0f)));
      }
    }
  return c;
}

// vmpray against Embree on primary + shadow; false if they disagree beyond
// the edges.
bool bench_embree(const std::string& spec, const tracer::Database& db) {
  const std::vector<tracer::PrimRecord> prims = distinct_prims(db);
  const auto others = std::count_if(prims.begin(), prims.end(), [](const auto& p) { return !is_triangle(p); });
  if (others > 0) {
    std::printf("  embree          not compared: %lld of %zu primitives are spheres or cones, which Embree's\n"
                "                  triangle mesh cannot hold (%s:tRES tessellates them for both sides)\n",
                static_cast<long long>(others), prims.size(), spec.c_str());
    return true;
  }
  VmprayQueries ours(db);
  EmbreeQueries ref(prims);
  const HitCheck c = compare_hits(db.header, ours, ref);
  Series s_ours, s_ref;
  for (int rep = 0; rep < kRepeats; ++rep) {
    s_ours.add(primary_shadow(db.header, ours));
    s_ref.add(primary_shadow(db.header, ref));
  }
  std::printf("  primary+shadow  vmpray %6.2f  embree %6.2f Mrays/s  time vmpray/embree %.3f  (%llu, %llu rays)\n",
              s_ours.mrays(), s_ref.mrays(), s_ours.median_seconds() / s_ref.median_seconds(),
              static_cast<unsigned long long>(s_ours.last.rays), static_cast<unsigned long long>(s_ref.last.rays));
  const auto line = [](const char* what, const HitCount& n) {
    std::printf("                  %-22s vmpray %7llu  embree %7llu  of %7llu;"
                " %llu rays differ, %llu away from an edge\n",
                what, static_cast<unsigned long long>(n.ours), static_cast<unsigned long long>(n.embree),
                static_cast<unsigned long long>(n.rays), static_cast<unsigned long long>(n.differ),
                static_cast<unsigned long long>(n.off_edge));
  };
  line("eye rays hitting", c.eye);
  line("shadow rays occluded", c.shadow);
  const bool ok = c.eye.off_edge == 0 && c.shadow.off_edge == 0;
  if (!ok)
    report_failure(spec, "vmpray and Embree disagree on rays away from any edge, at " +
                             std::to_string(db.header.page_size) + "-byte pages");
  return ok;
}
#endif

// ---- the uniform grid against the BVH ----

float grid_density = tracer::BuildOptions{}.grid_density;  // --density D
bool with_povray = false;  // `povray` is on the PATH and --no-povray was not given

void print_per_ray(const tracer::Database& db, bool is_grid) {
  tracer::InMemoryPageSource pages(db);
  tracer::RayStats stats;
  tracer::render_frame(db.header, pages, {}, stats);
  const double rays = double(stats.rays());
  std::printf("                  %s per ray: %.1f %s, %.1f primitive tests, %.1f page() calls\n",
              is_grid ? "grid" : "BVH ", double(stats.box_tests) / rays, is_grid ? "cells" : "boxes",
              double(stats.prim_tests) / rays, double(stats.page_calls) / rays);
}

// The grid against the BVH (both 1 KB pages) on the same rays, their runs
// alternating; false if a hit count or an image differs.
bool bench_grid(const std::string& spec, const tracer::Scene& scene, const tracer::Database& bvh) {
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
  Series bvh_ps, grid_ps, bvh_w, grid_w;
  std::vector<tracer::Color> reference, image;
  std::uint64_t calls = 0;
  bool same_hits = true, same = true;
  for (int rep = 0; rep < kRepeats; ++rep) {
    bvh_ps.add(vmpray_primary_shadow(bvh));
    grid_ps.add(vmpray_primary_shadow(grid));
    same_hits = same_hits && grid_ps.last.hits == bvh_ps.last.hits && grid_ps.last.shadowed == bvh_ps.last.shadowed;
    bvh_w.add(whitted(bvh, nullptr, calls, image));
    if (reference.empty()) reference = image;
    same = same && same_image(image, reference);
    grid_w.add(whitted(grid, nullptr, calls, image));
    same = same && same_image(image, reference);
  }
  std::printf("  grid vs BVH     primary+shadow grid %6.2f  BVH %6.2f Mrays/s  time grid/BVH %.3f  %s\n",
              grid_ps.mrays(), bvh_ps.mrays(), grid_ps.median_seconds() / bvh_ps.median_seconds(),
              same_hits ? "same hits" : "HITS DIFFER");
  std::printf("                  whitted        grid %6.2f  BVH %6.2f Mrays/s  time grid/BVH %.3f  %s\n",
              grid_w.mrays(), bvh_w.mrays(), grid_w.median_seconds() / bvh_w.median_seconds(),
              same ? "same image" : "IMAGES DIFFER");
  if (!same_hits) report_failure(spec, "the grid's hit counts differ from the BVH's at 1024-byte pages");
  if (!same) report_failure(spec, "the grid's Whitted image differs from the BVH's at 1024-byte pages");
  print_per_ray(grid, true);
  print_per_ray(bvh, false);
  return same_hits && same;
}

// ---- one scene ----

// The Whitted render at each page size and from direct access, their runs
// in turn; false if an image differs from the first 1 KB render.
bool bench_page_sizes(const std::string& spec, const tracer::Scene& scene, const tracer::Database& db) {
  const tracer::Database small = build_database(scene, {.page_size = 256});
  const tracer::Database big = build_database(scene, {.page_size = 65536});
  ContiguousPageSource direct(big);
  struct Variant {
    const tracer::Database* db;
    tracer::PageSource* direct;
    Series times;
    std::uint64_t page_calls = 0;
    bool same = true;
  };
  Variant v[] = {{&db, nullptr, {}}, {&small, nullptr, {}}, {&big, nullptr, {}}, {&big, &direct, {}}};
  std::vector<tracer::Color> reference, image;
  for (int rep = 0; rep < kRepeats; ++rep)
    for (Variant& x : v) {
      x.times.add(whitted(*x.db, x.direct, x.page_calls, image));
      if (reference.empty()) reference = image;
      x.same = x.same && same_image(image, reference);
    }
  const double base = v[0].times.median_seconds();
  bool ok = true;
  for (const Variant& x : v) {
    const unsigned ps = x.db->header.page_size;
    const double calls = double(x.page_calls) / double(x.times.last.rays);
    if (&x == &v[0])
      std::printf("  whitted @ 1024  vmpray %6.2f Mrays/s (%llu rays, %.3f s, %.2f page() calls/ray)  %s\n",
                  x.times.mrays(), static_cast<unsigned long long>(x.times.last.rays), base, calls,
                  x.same ? "same image every run" : "IMAGES DIFFER");
    else if (x.direct)
      std::printf("  whitted direct  vmpray %6.2f Mrays/s  paging overhead (1 KB paged / direct time) %.3f  %s\n",
                  x.times.mrays(), base / x.times.median_seconds(), x.same ? "same image" : "IMAGES DIFFER");
    else
      std::printf("  whitted @%5u  vmpray %6.2f Mrays/s (%.2f page() calls/ray)  time vs 1024: %.3f  %s\n", ps,
                  x.times.mrays(), calls, x.times.median_seconds() / base, x.same ? "same image" : "IMAGES DIFFER");
    if (!x.same)
      report_failure(spec, "Whitted image at " + std::to_string(ps) + "-byte pages" +
                               (x.direct ? " (direct access)" : "") + " differs from the 1024-byte reference");
    ok = ok && x.same;
  }
  return ok;
}

// ---- POV-Ray on the same scene ----

// vmpray's Whitted render at 1 KB pages and POV-Ray's trace of the same
// scene, their runs alternating; false if POV-Ray fails.
bool bench_povray(const std::string& spec, const tracer::Scene& scene, const tracer::Database& db) {
  char dir[] = "/tmp/tracer_bench.XXXXXX";
  if (!::mkdtemp(dir)) {
    report_failure(spec, "cannot make a temporary folder for POV-Ray's scene");
    return false;
  }
  const std::string pov = std::string(dir) + "/scene.pov";
  std::string error;
  Series ours;
  std::vector<double> theirs, parse;
  bench::PovRun run;
  if (bench::write_pov(scene, pov, error))
    for (int rep = 0; rep < kRepeats && error.empty(); ++rep) {
      std::uint64_t calls = 0;
      std::vector<tracer::Color> image;
      ours.add(whitted(db, nullptr, calls, image));
      run = bench::run_povray(pov, scene.camera.width, scene.camera.height);
      if (!run.ok) error = run.error;
      theirs.push_back(run.trace_seconds);
      parse.push_back(run.parse_seconds);
    }
  std::remove(pov.c_str());
  ::rmdir(dir);
  if (!error.empty()) {
    report_failure(spec, "POV-Ray: " + error);
    return false;
  }
  // POV-Ray counts eye, reflected and refracted rays, not shadow rays.
  std::printf("  whitted povray  trace %.3f s, vmpray %.3f s: time povray/vmpray %.2f  (rays but shadow rays: "
              "povray %llu, vmpray %llu; povray's parse %.2f s)\n",
              median(theirs), ours.median_seconds(), median(theirs) / ours.median_seconds(),
              static_cast<unsigned long long>(run.rays),
              static_cast<unsigned long long>(ours.last.rays - ours.last.shadow), median(parse));
  return true;
}

// false if any check failed.
bool bench_scene(const std::string& spec, bool grid_only) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = scene.camera.height = 512;
  const tracer::Database db = build_database(scene, {.page_size = 1024});
  std::printf("%-9s %8llu prims  BVH build %.3f s  %6u pages (%.0f KB)\n", spec.c_str(),
              static_cast<unsigned long long>(db.header.primitive_count), db.stats.accel_seconds,
              db.header.page_count, db.header.bytes() / 1024.0);
  if (grid_only) return bench_grid(spec, scene, db);
  bool ok = true;
#ifdef VMPRAY_HAVE_EMBREE
  ok = bench_embree(spec, db) && ok;
#else
  std::printf("  embree          not built (libembree-dev was missing when the build was configured)\n");
#endif
  ok = bench_page_sizes(spec, scene, db) && ok;
  if (with_povray) ok = bench_povray(spec, scene, db) && ok;
  return bench_grid(spec, scene, db) && ok;
}

// ---- triangulation ----

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
// grow with the polygon. False if a wheel gives other than n - 2 triangles.
bool bench_triangulation() {
  std::printf("concave polygon triangulation (toothed wheels), median of %d runs:\n", kRepeats);
  bool ok = true;
  for (int teeth : {500, 2000, 8000}) {
    const std::vector<tracer::Vec3d> v = toothed_wheel(teeth);
    std::vector<double> seconds;
    std::size_t triangles = 0;
    for (int rep = 0; rep < kRepeats; ++rep) {
      const double t0 = cpu_seconds();
      triangles = tracer::triangulate_polygon(v).size();
      seconds.push_back(cpu_seconds() - t0);
    }
    const double t = median(seconds);
    const bool right = triangles == v.size() - 2;
    std::printf("  %6zu vertices  %8.3f ms  %6.1f ns per vertex  %s\n", v.size(), t * 1e3, t * 1e9 / double(v.size()),
                right ? "n - 2 triangles" : "WRONG COUNT");
    if (!right) report_failure("toothed wheel", std::to_string(triangles) + " triangles from " +
                                                    std::to_string(v.size()) + " vertices");
    ok = ok && right;
  }
  return ok;
}

}  // namespace

const char* const usage =
    "usage: tracer_bench [--grid] [--no-povray] [--density CELLS_PER_PRIMITIVE] [SCENE...]\n"
    "  (default scenes teapot mountain rings4 tetra9; density above 0, at most 64;\n"
    "  POV-Ray 3.7 is timed on the same scenes when `povray` is on the PATH)\n";

int bench_tracer(const std::vector<std::string>& args) {
  std::vector<std::string> scenes;
  bool grid_only = false, no_povray = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--grid") {
      grid_only = true;
    } else if (args[i] == "--no-povray") {
      no_povray = true;
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
  const bool want_povray = !grid_only && !no_povray;
  with_povray = want_povray && bench::povray_available();
  for (const auto& s : scenes) tracer::generate_scene(s);  // an unknown scene fails before any work
  std::printf("tracer_bench: one thread, 512x512, CPU time of the thread; each figure the median of %d runs,\n"
              "the runs of a comparison alternating, ratios of medians; images checked against the 1 KB render\n",
              kRepeats);
#ifdef VMPRAY_HAVE_EMBREE
  std::printf("and hit counts against Embree's, rays told apart only within %g of a triangle's edge\n",
              double(kEdge));
#endif
  if (want_povray && !with_povray)
    std::printf("povray is not on the PATH: POV-Ray is not timed (Debian package povray)\n");
  bool ok = true;
  for (const auto& s : scenes) ok = bench_scene(s, grid_only) && ok;
  if (!grid_only) ok = bench_triangulation() && ok;
  return ok ? 0 : 1;
}

int main(int argc, char** argv) { return bench::run_main("tracer_bench", usage, argc, argv, bench_tracer); }
