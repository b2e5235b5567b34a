// The run report: what was rendered, the database, rays and timing, and for
// a machine run its pages, network and per-node work; printed for people and
// written as JSON (same fields) for scripts.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "app/render/machine_summary.hpp"
#include "tracer/database.hpp"
#include "tracer/stats.hpp"

namespace app {

// The --stats document's layout: raised when a field changes meaning or goes.
inline constexpr int stats_schema_version = 2;

struct RunReport {
  std::string version;                    // of vmpray
  std::vector<std::string> command_line;  // as typed: the program, then its arguments
  std::string scene;
  std::string output;
  int width = 0, height = 0;
  bool spd_procedure = false;
  bool shadow_rays_all = false;  // one shadow ray per light at every hit
  std::uint64_t polygons = 0;    // "p" + "pp" entities
  std::uint64_t objects = 0;
  std::uint64_t primitives = 0;  // after triangulation
  tracer::Accel accel = tracer::Accel::bvh;
  tracer::BvhLayout bvh_layout = tracer::BvhLayout::treelet;  // meaningful for the BVH only
  std::uint32_t page_size = 0;
  std::uint32_t pages = 0;
  std::uint64_t database_bytes = 0;  // pages * page_size
  tracer::BuildStats build;
  double load_seconds = 0;
  double render_seconds = 0;
  unsigned render_threads = 0;  // the single-process renderer's threads; 0 for a machine (its summary has them)
  tracer::RayStats rays;
  std::optional<MachineSummary> machine;  // none for the single-process renderer

  double mrays_per_second() const {
    return render_seconds > 0 ? double(rays.rays()) / render_seconds * 1e-6 : 0.0;
  }
};

void print_report(std::ostream& out, const RunReport& r);
// j as JSON text (indent < 0: one line); bytes that are not UTF-8 become U+FFFD.
std::string dump_json(const Json& j, int indent = -1);
// The report as the JSON document --stats writes.
std::string stats_json(const RunReport& r);

}  // namespace app
