// Human-readable and JSON forms of RunReport.
#include "app/render/run_report.hpp"

#include <iomanip>

#include "app/render/options.hpp"
#include "app/render/wording.hpp"

namespace app {

// JSON text is UTF-8 (RFC 8259): a byte that is not part of a well-formed
// sequence, as in a file name in Latin-1, becomes U+FFFD.
std::string dump_json(const Json& j, int indent) { return j.dump(indent, ' ', false, Json::error_handler_t::replace); }

void print_report(std::ostream& out, const RunReport& r) {
  const auto& s = r.rays;
  out << std::fixed << std::setprecision(2);
  out << "scene          " << r.scene << ": " << r.polygons << " polygons, " << r.objects << " objects, "
      << r.primitives << " primitives\n"
      << "image          " << r.output << " (" << r.width << "x" << r.height
      << (r.spd_procedure ? ", SPD procedure" : "") << ")\n"
      << "database       " << r.pages << " pages of " << r.page_size
      << " bytes = " << size_text(double(r.database_bytes)) << " (" << accel_description(r.accel, r.bvh_layout)
      << ", built in " << r.build.accel_seconds << " s)\n"
      << "rays           " << s.rays() << ": primary " << s.primary << " (hit " << s.primary_hits << "), shadow "
      << s.shadow << ", reflected " << s.reflected << ", refracted " << s.refracted
      << (r.shadow_rays_all ? " (shadow rays to every light)" : "") << "\n"
      << "tests          " << s.box_tests << (r.accel == tracer::Accel::bvh ? " box" : " cell") << ", " << s.prim_tests
      << " primitive\n"
      << "page accesses  " << s.record_reads << " record reads, " << s.page_calls << " page calls, "
      << s.pages_per_sample() << " distinct pages per " << (r.spd_procedure ? "sample" : "pixel") << "\n"
      << "time           load " << r.load_seconds << " s, build "
      << r.build.triangulate_seconds + r.build.accel_seconds + r.build.pack_seconds << " s, render " << r.render_seconds
      << " s" << (r.render_threads > 1 ? " on " + std::to_string(r.render_threads) + " threads" : std::string()) << ", "
      << r.mrays_per_second() << " Mrays/s\n";
  if (r.machine) print_machine_report(out, *r.machine);
}

std::string stats_json(const RunReport& r) {
  const auto& s = r.rays;
  Json j = {{"schema_version", stats_schema_version},
            {"vmpray_version", r.version},
            {"command_line", r.command_line},
            {"scene", r.scene},
            {"output", r.output},
            {"width", r.width},
            {"height", r.height},
            {"spd_procedure", r.spd_procedure},
            {"shadow_rays", r.shadow_rays_all ? "all" : "facing"},
            {"polygons", r.polygons},
            {"objects", r.objects},
            {"primitives", r.primitives},
            {"database",
             {{"accel", accel_name(r.accel)},
              {"bvh_layout", bvh_layout_name(r.bvh_layout)},
              {"page_size", r.page_size},
              {"pages", r.pages},
              {"bytes", r.database_bytes},
              {"payload_bytes", r.build.payload_bytes},
              {"bvh_nodes", r.build.bvh_nodes},
              {"grid_cells", r.build.grid_cells}}},
            {"rays",
             {{"total", s.rays()},
              {"primary", s.primary},
              {"primary_hits", s.primary_hits},
              {"shadow", s.shadow},
              {"reflected", s.reflected},
              {"refracted", s.refracted}}},
            {"tests", {{"box", s.box_tests}, {"primitive", s.prim_tests}}},
            {"pages",
             {{"record_reads", s.record_reads},
              {"page_calls", s.page_calls},
              {"samples", s.samples},
              {"distinct_pages", s.distinct_pages},
              {"per_sample", s.pages_per_sample()}}},
            {"seconds",
             {{"load", r.load_seconds},
              {"triangulate", r.build.triangulate_seconds},
              {"accel_build", r.build.accel_seconds},
              {"pack", r.build.pack_seconds},
              {"render", r.render_seconds}}},
            {"mrays_per_second", r.mrays_per_second()}};
  if (r.render_threads > 0) j["render_threads"] = r.render_threads;
  if (r.machine) j["machine"] = machine_json(*r.machine);
  return dump_json(j, 2) + "\n";
}

}  // namespace app
