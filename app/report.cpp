// Human-readable and JSON forms of RunReport.
#include "app/report.hpp"

#include <cstdio>
#include <iomanip>
#include <sstream>

#include "app/options.hpp"
#include "app/wording.hpp"

namespace app {

namespace {

// The length of the well-formed UTF-8 sequence at s[i] (RFC 3629: no
// overlong forms, no surrogates, nothing above U+10FFFF), 0 if there is none.
std::size_t utf8_sequence(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  std::size_t length = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (b < 0x80) return 1;
  if (b >= 0xc2 && b <= 0xdf) length = 2;
  else if (b >= 0xe0 && b <= 0xef) length = 3, lo = b == 0xe0 ? 0xa0 : 0x80, hi = b == 0xed ? 0x9f : 0xbf;
  else if (b >= 0xf0 && b <= 0xf4) length = 4, lo = b == 0xf0 ? 0x90 : 0x80, hi = b == 0xf4 ? 0x8f : 0xbf;
  else return 0;
  if (i + length > s.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < length; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xbf) return 0;
  return length;
}

}  // namespace

// JSON text is UTF-8 (RFC 8259): a byte that is not part of a well-formed
// sequence, as in a file name in Latin-1, becomes U+FFFD.
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    const std::size_t length = utf8_sequence(s, i);
    if (length == 0) {
      out += "\\ufffd";
      ++i;
      continue;
    }
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else out.append(s, i, length);
    i += length;
  }
  return out + "\"";
}

void print_report(std::ostream& out, const RunReport& r) {
  const auto& s = r.rays;
  out << std::fixed << std::setprecision(2);
  out << "scene          " << r.scene << ": " << r.polygons << " polygons, " << r.objects
      << " objects, " << r.primitives << " primitives\n"
      << "image          " << r.output << " (" << r.width << "x" << r.height
      << (r.spd_procedure ? ", SPD procedure" : "") << ")\n"
      << "database       " << r.pages << " pages of " << r.page_size << " bytes = "
      << size_text(double(r.database_bytes)) << " (" << accel_description(r.accel, r.bvh_layout) << ", built in "
      << r.build.accel_seconds << " s)\n"
      << "rays           " << s.rays() << ": primary " << s.primary << " (hit " << s.primary_hits
      << "), shadow " << s.shadow << ", reflected " << s.reflected << ", refracted "
      << s.refracted << (r.shadow_rays_all ? " (shadow rays to every light)" : "") << "\n"
      << "tests          " << s.box_tests << (r.accel == tracer::Accel::bvh ? " box" : " cell")
      << ", " << s.prim_tests << " primitive\n"
      << "page accesses  " << s.record_reads << " record reads, " << s.page_calls
      << " page calls, " << s.pages_per_sample() << " distinct pages per "
      << (r.spd_procedure ? "sample" : "pixel") << "\n"
      << "time           load " << r.load_seconds << " s, build "
      << r.build.triangulate_seconds + r.build.accel_seconds + r.build.pack_seconds
      << " s, render " << r.render_seconds << " s, " << r.mrays_per_second() << " Mrays/s\n";
  if (r.machine) print_machine_report(out, *r.machine);
}

std::string stats_json(const RunReport& r) {
  std::ostringstream f;
  const auto& s = r.rays;
  f << std::setprecision(9) << "{\n"
    << "  \"scene\": " << json_string(r.scene) << ",\n"
    << "  \"output\": " << json_string(r.output) << ",\n"
    << "  \"width\": " << r.width << ", \"height\": " << r.height << ",\n"
    << "  \"spd_procedure\": " << (r.spd_procedure ? "true" : "false") << ",\n"
    << "  \"shadow_rays\": \"" << (r.shadow_rays_all ? "all" : "facing") << "\",\n"
    << "  \"polygons\": " << r.polygons << ", \"objects\": " << r.objects
    << ", \"primitives\": " << r.primitives << ",\n"
    << "  \"database\": {\"accel\": \"" << accel_name(r.accel) << "\", \"bvh_layout\": \""
    << bvh_layout_name(r.bvh_layout) << "\", \"page_size\": "
    << r.page_size << ", \"pages\": " << r.pages << ", \"bytes\": " << r.database_bytes
    << ", \"payload_bytes\": " << r.build.payload_bytes << ", \"bvh_nodes\": "
    << r.build.bvh_nodes << ", \"grid_cells\": " << r.build.grid_cells << "},\n"
    << "  \"rays\": {\"total\": " << s.rays() << ", \"primary\": " << s.primary
    << ", \"primary_hits\": " << s.primary_hits << ", \"shadow\": " << s.shadow
    << ", \"reflected\": " << s.reflected << ", \"refracted\": " << s.refracted << "},\n"
    << "  \"tests\": {\"box\": " << s.box_tests << ", \"primitive\": " << s.prim_tests << "},\n"
    << "  \"pages\": {\"record_reads\": " << s.record_reads << ", \"page_calls\": "
    << s.page_calls << ", \"samples\": " << s.samples << ", \"distinct_pages\": "
    << s.distinct_pages << ", \"per_sample\": " << s.pages_per_sample() << "},\n"
    << "  \"seconds\": {\"load\": " << r.load_seconds << ", \"triangulate\": "
    << r.build.triangulate_seconds << ", \"accel_build\": " << r.build.accel_seconds
    << ", \"pack\": " << r.build.pack_seconds << ", \"render\": " << r.render_seconds << "},\n"
    << "  \"mrays_per_second\": " << r.mrays_per_second();
  if (r.machine) {
    f << ",\n  \"machine\": ";
    write_machine_json(f, *r.machine, "  ");
  }
  f << "\n}\n";
  return f.str();
}

}  // namespace app
