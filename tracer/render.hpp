// Whitted ray tracing over a paged database: the code a processor runs to turn
// a pixel (or an SPD corner sample) into a colour; the shading model is
// described at class Tracer.
//
// Invariants:
//  - A Tracer reads the scene only through its PageSource (plus the replicated
//    DatabaseHeader). It copies every record out of the page (memcpy) before
//    its next page() call, honouring the PageSource contract, and it calls
//    page() only when a record lies outside the page it read last.
//  - A pixel's colour depends only on (x, y), the header and the page
//    contents: no global state, no random numbers, so an image is identical
//    however its pixels are distributed over tracers, and for every page size.
//  - A Tracer is single-threaded; use one per fiber or thread.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "tracer/camera.hpp"
#include "tracer/database.hpp"
#include "tracer/stats.hpp"

namespace tracer {

struct TraceOptions {
  int max_depth = 5;                     // the eye ray is depth 1
  float min_contribution = 1.0f / 256;   // adaptive depth cut-off (not in SPD mode)
  bool spd_procedure = false;            // SPD testing procedure (see NFF.md)
  bool shadow_rays_to_all_lights = false;  // also cast the shadow rays N.L <= 0 makes useless
};

// The closest hit of a ray: distance, barycentrics and the primitive record.
struct Hit {
  float t = 0;
  float u = 0, v = 0;
  std::uint32_t prim_index = 0;
  PrimRecord prim{};
};

// Shading (NFF): per positional light, Kd * colour * (N.L) + Ks * (R.V)^Shine,
// no ambient term; light intensity 1/sqrt(#lights) (SPD's convention).
// Shadow rays: every object, transmitting ones included, blocks light fully
// (as SPD-style renderers do); no shadow ray where N.L <= 0 unless
// shadow_rays_to_all_lights (which changes the counts, never the image).
// Reflection (weight Ks) when Ks > 0; refraction (weight T, Snell's law, IOR
// of the material inside, 1 outside) when T > 0; under total internal
// reflection the T weight goes to the reflection ray. Surfaces are two-sided:
// the shading normal is turned to face the incoming ray. Outside SPD mode a
// secondary ray is skipped when its weight along the path falls below
// min_contribution.
class Tracer {
 public:
  // header and pages must outlive the Tracer.
  Tracer(const DatabaseHeader& header, PageSource& pages, TraceOptions options = {});

  // Colour of pixel (x, y), one eye ray through its centre.
  Color trace_pixel(int x, int y, RayStats& stats);
  // SPD corner sample (sx, sy), 0 <= sx <= width, 0 <= sy <= height: pixel
  // (x, y) is average_corners of samples (x, y), (x+1, y), (x, y+1), (x+1, y+1).
  Color trace_sample(int sx, int sy, RayStats& stats);
  static Color average_corners(const Color& c00, const Color& c10, const Color& c01,
                               const Color& c11);

  // Ray queries, public for tests and benchmarks.
  std::optional<Hit> closest_hit(const Ray& ray, float t_min, float t_max, RayStats& stats);
  bool occluded(const Ray& ray, float t_min, float t_max, RayStats& stats);

  // Called before every ray the two queries above cast, with `context`; none
  // by default. It may suspend the caller, provided nothing else reads this
  // Tracer's PageSource meanwhile: the page read last stays in use.
  using RayHook = void (*)(void* context);
  void set_ray_hook(RayHook hook, void* context) {
    ray_hook_ = hook;
    ray_hook_context_ = context;
  }

 private:
  // Where record `index` of a section lies; valid until the next page read.
  const std::byte* locate(Section section, std::uint64_t index, std::size_t size, RayStats& stats);
  template <class T> T read(Section section, std::uint64_t index, RayStats& stats);
  const std::byte* fetch(PageId id, RayStats& stats);
  void begin_sample();
  void end_sample(RayStats& stats);
  Color trace_eye(const Ray& ray, RayStats& stats);

  // Traversal; Any = stop at the first hit (shadow rays).
  template <bool Any> bool traverse_bvh(const Ray& ray, float t_min, float& t_max, Hit* hit, RayStats& stats);
  template <bool Any> bool traverse_grid(const Ray& ray, float t_min, float& t_max, Hit* hit, RayStats& stats);
  template <bool Any> bool test_leaf(std::uint32_t first, std::uint32_t count, const Ray& ray, float t_min,
                                      float& t_max, Hit* hit, RayStats& stats);
  // Up to four records of a leaf in one page.
  template <bool Any> bool test_run(std::uint32_t first, std::uint32_t count, const Ray& ray, float t_min,
                                     float& t_max, Hit* hit, RayStats& stats);
  template <bool Any> bool test_prim(std::uint32_t index, const Ray& ray, float t_min, float& t_max, Hit* hit, RayStats& stats);
  template <bool Any>
  bool test_record(const PrimRecord& p, std::uint32_t index, const Ray& ray, float t_min, float& t_max, Hit* hit,
                   RayStats& stats);
  // A grid cell's primitives, each tested at most once per ray (the mailbox).
  template <bool Any>
  bool test_cell(const GridCell& cell, std::uint64_t ray_tag, const Ray& ray, float t_min, float& t_max, Hit* hit,
                 RayStats& stats);
  template <bool Any, bool Top>
  bool walk_grid(const Box3f& box, const int dims[3], std::uint64_t base, float t_enter, const Ray& ray,
                 const RayInverse& inv, std::uint64_t ray_tag, float t_min, float& t_max, Hit* hit, RayStats& stats);
  std::uint64_t next_ray_tag();

  // Shading (shading.cpp).
  Color shade(const Ray& ray, int depth, float weight, RayStats& stats);
  Color shade_hit(const Ray& ray, const Hit& hit, int depth, float weight, RayStats& stats);
  Color direct_light(const Vec3f& p, const Vec3f& n_geo, const Vec3f& n, const Vec3f& view,
                     const MaterialRecord& m, RayStats& stats);

  const DatabaseHeader& header_;
  PageSource& pages_;
  TraceOptions options_;
  CameraModel camera_;
  static constexpr PageId kNoPage = ~PageId{0};  // never a page id: a database has fewer than 2^32 pages
  PageId last_page_ = kNoPage;
  const std::byte* last_ptr_ = nullptr;  // page last_page_ unless that is kNoPage
  std::vector<std::uint32_t> page_stamp_;  // sample generation that last touched each page
  std::uint32_t generation_ = 0;
  std::uint64_t sample_pages_ = 0;
  struct StackEntry {
    std::uint32_t child, count;
    float t;
  };
  std::vector<StackEntry> stack_;
  // Grid mailbox: slot (id mod kMailboxSlots) holds (ray id << 32 | id) of the
  // last primitive put there, so a ray tests a primitive listed in several
  // cells once (a collision only costs a second test). Per tracer, never in
  // the shared pages; empty for a BVH database.
  static constexpr std::size_t kMailboxSlots = 1024;
  std::vector<std::uint64_t> mailbox_;
  std::uint32_t ray_id_ = 0;
  RayHook ray_hook_ = nullptr;
  void* ray_hook_context_ = nullptr;
};

// Renders a whole frame sequentially into row-major pixels (y = 0 at the top);
// in SPD mode from (W+1) x (H+1) corner samples. `progress(rows_done)` is
// called after each row when given.
std::vector<Color> render_frame(const DatabaseHeader& header, PageSource& pages,
                                const TraceOptions& options, RayStats& stats,
                                const std::function<void(int)>& progress = {});

// The same frame on `threads` OS threads (0 and 1: the calling thread only),
// each with its own Tracer over db's pages in memory, taking rows in order
// from a shared counter. The pixels and the stats are render_frame's for
// any thread count: a pixel depends only on (x, y), and the stats are sums
// of per-sample counts (a Tracer forgets its last page at every sample).
// In SPD mode each corner sample is traced once, as there: bands of rows of
// samples are traced in parallel, then averaged. `progress(rows_done)` is
// called on the calling thread only, with counts that never decrease, the
// last of them h. An
// exception on any thread is rethrown here once all have stopped.
std::vector<Color> render_frame(const Database& db, const TraceOptions& options, RayStats& stats, unsigned threads,
                                const std::function<void(int)>& progress = {});

}  // namespace tracer
