// POV-Ray 3.7 scene writer and runner for tracer_bench (see pov_scene.hpp).
#include "examples/bench/pov_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <sstream>
#include <variant>
#include <vector>

#include "tracer/geometry.hpp"

namespace bench {
namespace {

std::string vec(const tracer::Vec3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "<%.9g,%.9g,%.9g>", v.x, v.y, v.z);
  return buf;
}

std::string rgb(const tracer::Color& c) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "rgb <%.9g,%.9g,%.9g>", double(c.r), double(c.g), double(c.b));
  return buf;
}

// The texture of one NFF material: lit only by the lights, Kd diffuse, Ks
// both the highlight's weight and the mirror's, T passing light through.
std::string texture(const tracer::Material& m) {
  std::ostringstream out;
  out.precision(9);
  out << "texture { pigment { " << rgb(m.color);
  if (m.transmittance > 0) out << " transmit " << m.transmittance;
  out << " } finish { ambient 0 emission 0 diffuse " << m.kd;
  if (m.ks > 0) out << " phong " << m.ks << " phong_size " << std::max(m.shine, 1.0) << " reflection " << m.ks;
  out << " } }";
  if (m.transmittance > 0) out << " interior { ior " << m.ior << " }";
  return out.str();
}

// NFF's camera: `angle` spans the centres of the first and last pixels of the
// longer side. POV-Ray's `angle` spans the edges of the image's width, and
// `right -x` makes its frame right-handed like NFF's.
void write_camera(std::FILE* f, const tracer::Camera& c) {
  const double half = std::tan(c.angle_deg * std::numbers::pi / 360.0);
  const double step = 2.0 * half / std::max(1, std::max(c.width, c.height) - 1);
  const double pov_angle = 2.0 * std::atan(step * c.width / 2.0) * 180.0 / std::numbers::pi;
  std::fprintf(f, "camera { perspective location %s sky %s up y right -x*%.9g look_at %s angle %.9g }\n",
               vec(c.from).c_str(), vec(c.up).c_str(), double(c.width) / c.height, vec(c.at).c_str(), pov_angle);
}

}  // namespace

bool write_pov(const tracer::Scene& scene, const std::string& path, std::string& error) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    error = path + ": cannot write";
    return false;
  }
  std::fprintf(f, "#version 3.7;\nglobal_settings { assumed_gamma 1 max_trace_level 5 adc_bailout 1/256 "
                  "ambient_light 0 }\n");
  std::fprintf(f, "background { %s }\n", rgb(scene.background).c_str());
  write_camera(f, scene.camera);
  // SPD's convention, as the database keeps it: each light at 1/sqrt(lights).
  const float intensity = 1.0f / std::sqrt(float(std::max<std::size_t>(1, scene.lights.size())));
  for (const tracer::Light& l : scene.lights)
    std::fprintf(f, "light_source { %s %s }\n", vec(l.position).c_str(), rgb(l.color * intensity).c_str());
  std::vector<std::string> textures;
  for (const tracer::Material& m : scene.materials) textures.push_back(texture(m));
  // Triangles go into one mesh per material, written after the other shapes.
  std::map<std::uint32_t, std::vector<std::string>> meshes;
  for (const tracer::Object& o : scene.objects) {
    const std::string& tex = textures.at(o.material);
    if (const auto* s = std::get_if<tracer::Sphere>(&o.shape)) {
      std::fprintf(f, "sphere { %s, %.9g %s }\n", vec(s->center).c_str(), std::abs(s->radius), tex.c_str());
    } else if (const auto* c = std::get_if<tracer::Cone>(&o.shape)) {
      std::fprintf(f, "cone { %s, %.9g, %s, %.9g open %s }\n", vec(c->base).c_str(), std::abs(c->base_radius),
                   vec(c->apex).c_str(), std::abs(c->apex_radius), tex.c_str());
    } else if (const auto* p = std::get_if<tracer::Polygon>(&o.shape)) {
      for (const auto& t : tracer::triangulate_polygon(tracer::points(p->vertices)))
        meshes[o.material].push_back("triangle { " + vec(p->vertices[t[0]]) + "," + vec(p->vertices[t[1]]) +
                                     "," + vec(p->vertices[t[2]]) + " }");
    } else if (const auto* q = std::get_if<tracer::Patch>(&o.shape)) {
      for (const auto& t : tracer::triangulate_polygon(tracer::points(q->vertices))) {
        std::string tri = "smooth_triangle { ";
        for (int k = 0; k < 3; ++k)
          tri += (k ? "," : "") + vec(q->vertices[t[k]]) + "," + vec(q->normals[t[k]]);
        meshes[o.material].push_back(tri + " }");
      }
    }
  }
  for (const auto& [material, triangles] : meshes) {
    std::fprintf(f, "mesh {\n");
    for (const std::string& t : triangles) std::fprintf(f, "%s\n", t.c_str());
    std::fprintf(f, "%s }\n", textures[material].c_str());
  }
  const bool written = std::fflush(f) == 0 && !std::ferror(f);
  if (std::fclose(f) != 0 || !written) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

bool povray_available() { return std::system("command -v povray >/dev/null 2>&1") == 0; }

namespace {

// The number in "(X seconds)" on the line that starts with `label`, or -1.
double seconds_after(const std::string& log, const std::string& label) {
  const std::size_t at = log.find(label);
  if (at == std::string::npos) return -1;
  const std::size_t open = log.find('(', at);
  return open == std::string::npos ? -1 : std::atof(log.c_str() + open + 1);
}

}  // namespace

PovRun run_povray(const std::string& pov_path, int width, int height) {
  PovRun run;
  const std::string command = "povray +I'" + pov_path + "' -F -D -P -A +WT1 +V +W" + std::to_string(width) +
                              " +H" + std::to_string(height) + " 2>&1";
  std::FILE* p = ::popen(command.c_str(), "r");
  if (!p) {
    run.error = "cannot start povray";
    return run;
  }
  std::string log;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) log.append(buf, n);
  const int status = ::pclose(p);
  // "Trace Time: ... (W seconds)" and then "using 1 thread(s) with C CPU-seconds total".
  const std::size_t trace = log.find("Trace Time:");
  const std::size_t cpu = trace == std::string::npos ? trace : log.find("thread(s) with ", trace);
  const std::size_t rays = log.find("Rays:");
  if (status != 0 || cpu == std::string::npos || rays == std::string::npos) {
    const std::size_t last = log.find_last_not_of('\n');
    const std::size_t line = last == std::string::npos ? 0 : log.rfind('\n', last);
    run.error = "povray failed (exit status " + std::to_string(status) + "): " +
                log.substr(line == std::string::npos ? 0 : line + 1, 200);
    return run;
  }
  run.trace_seconds = std::atof(log.c_str() + cpu + std::string("thread(s) with ").size());
  run.parse_seconds = seconds_after(log, "Parse Time:");
  run.rays = std::strtoull(log.c_str() + rays + 5, nullptr, 10);
  run.ok = true;
  return run;
}

}  // namespace bench
