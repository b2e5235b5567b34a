// libFuzzer target for the NFF parser and the database build behind it: any
// input either throws SceneError or parses into a scene meeting scene.hpp's
// invariants, whose database then builds with either accelerator (polygons
// triangulated, BVH or grid built, records packed) or is refused with
// DatabaseError; anything else (a crash, a sanitizer report, another
// exception) is a finding. Inputs are capped so memory stays bounded: 64 KiB
// of text, or 4 KiB of gzip (which inflates at most ~1000-fold).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "tracer/database.hpp"
#include "tracer/nff.hpp"

namespace {

bool finite(const tracer::Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Aborts (a finding) if the parser returned a scene breaking an invariant.
void check_invariants(const tracer::Scene& scene) {
  bool ok = scene.camera.width >= 1 && scene.camera.height >= 1;
  for (const tracer::Object& o : scene.objects) {
    ok = ok && o.material < scene.materials.size();
    if (auto* p = std::get_if<tracer::Polygon>(&o.shape)) ok = ok && p->vertices.size() >= 3;
    if (auto* p = std::get_if<tracer::Patch>(&o.shape))
      ok = ok && p->vertices.size() >= 3 && p->normals.size() == p->vertices.size();
    if (auto* s = std::get_if<tracer::Sphere>(&o.shape)) ok = ok && s->radius != 0 && finite(s->center);
  }
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  bool gzip = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  if (size > (gzip ? 4096u : 65536u)) return -1;  // -1: keep out of the corpus
  std::string_view text(reinterpret_cast<const char*>(data), size);
  tracer::Scene scene;
  try {
    scene = tracer::parse_nff(text, "fuzz.nff");
  } catch (const tracer::SceneError&) {
    return 0;  // the expected outcome for malformed input
  }
  check_invariants(scene);
  for (const tracer::Accel accel : {tracer::Accel::bvh, tracer::Accel::grid}) {
    try {
      const tracer::Database db = tracer::build_database(scene, tracer::BuildOptions{.accel = accel});
      if (db.pages.size() != db.header.page_count) std::abort();
    } catch (const tracer::DatabaseError&) {
      // A scene too large for the database's references.
    }
  }
  return 0;
}
