// Single-process rendering; see single.hpp.
#include "app/single.hpp"

#include <chrono>

#include "app/progress.hpp"
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

RenderResult render_single(const Options& o, const tracer::Scene& scene) {
  const tracer::Database db = build_database(scene, build_options(o));
  RenderResult out{tracer::Image(scene.camera.width, scene.camera.height), describe_run(o, db)};
  tracer::InMemoryPageSource pages(db);
  const tracer::TraceOptions trace{.max_depth = o.max_depth,
                                   .spd_procedure = o.spd_procedure,
                                   .shadow_rays_to_all_lights = o.shadow_rays_all};
  const int w = scene.camera.width, h = scene.camera.height;
  ProgressBar bar(std::uint64_t(w) * h, "pixels", !o.quiet && stderr_is_terminal());
  const auto t0 = std::chrono::steady_clock::now();
  const auto pixels = tracer::render_frame(db.header, pages, trace, out.report.rays,
                                           [&](int rows) { bar.update(std::uint64_t(rows) * w); });
  out.report.render_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bar.finish();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.image.at(x, y) = pixels[std::size_t(y) * w + x];
  return out;
}

}  // namespace app
