// Single-process rendering; see single_run.hpp.
#include "app/render/single_run.hpp"

#include <algorithm>
#include <chrono>
#include <utility>
#include <vector>

#include "app/render/cpu_count.hpp"
#include "app/render/memory_check.hpp"
#include "app/render/progress.hpp"
#include "tracer/render.hpp"

namespace app {

RunReport describe_run(const Options& o, const tracer::Database& db) {
  const tracer::DatabaseHeader& h = db.header;
  RunReport r;
  r.scene = h.scene_name.empty() ? o.scene : h.scene_name;
  r.output = o.output;
  r.width = h.camera.width;
  r.height = h.camera.height;
  r.spd_procedure = o.spd_procedure;
  r.shadow_rays_all = o.shadow_rays_all;
  r.polygons = h.polygon_count;
  r.objects = h.object_count;
  r.primitives = h.primitive_count;
  r.accel = h.accel;
  r.bvh_layout = o.bvh_layout;
  r.page_size = h.page_size;
  r.pages = h.page_count;
  r.database_bytes = h.bytes();
  r.build = db.stats;
  return r;
}

RenderResult render_single(const Options& o, tracer::Scene scene) {
  const int w = scene.camera.width, h = scene.camera.height;
  const tracer::Database db = in_phase("building the database", !o.quiet && stderr_is_terminal(), [&] {
    return naming_memory_shortage("building the database",
                                  [&] { return build_database(std::move(scene), build_options(o)); });
  });
  RunReport report = describe_run(o, db);
  const tracer::TraceOptions trace{.max_depth = o.max_depth,
                                   .spd_procedure = o.spd_procedure,
                                   .shadow_rays_to_all_lights = o.shadow_rays_all};
  ProgressBar bar(std::uint64_t(w) * h, "pixels", !o.quiet && stderr_is_terminal());
  const auto t0 = std::chrono::steady_clock::now();
  // Rows are what the threads share out: more threads than rows would only wait.
  const unsigned threads = std::min<unsigned>(o.machine.threads.count == 0 ? usable_cpus() : o.machine.threads.count,
                                              unsigned(h));
  report.render_threads = threads;
  std::vector<tracer::Color> pixels =
      tracer::render_frame(db, trace, report.rays, threads, [&](int rows) { bar.update(std::uint64_t(rows) * w); });
  report.render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bar.finish();
  // The frame becomes the image: one image-sized buffer, not a second to copy it into.
  return {tracer::Image(w, h, std::move(pixels)), std::move(report)};
}

}  // namespace app
