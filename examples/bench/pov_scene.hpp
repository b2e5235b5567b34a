// The same scene for POV-Ray 3.7, so that tracer_bench can time vmpray's
// Whitted render beside POV-Ray's trace of it. write_pov maps the NFF model
// onto POV-Ray's: the camera's pixel rays (pixel centres, the same step), the
// point lights (at SPD's 1/sqrt(lights) each), Kd as diffuse, Ks as Phong highlight and mirror weight,
// T as transmit with the index of refraction, no ambient, the render's depth
// (5) and cut-off (1/256). Polygons are cut by vmpray's own triangulation and
// go, with patches as smooth triangles, into one mesh per material.
// run_povray renders on one thread with no antialiasing and no output file,
// and reads POV-Ray's trace time (CPU seconds) and ray count from its log.
#pragma once

#include <cstdint>
#include <string>

#include "tracer/scene.hpp"

namespace bench {

// Writes `scene` at its camera's width and height to `path`; false with
// `error` set if the file cannot be written.
bool write_pov(const tracer::Scene& scene, const std::string& path, std::string& error);

struct PovRun {
  bool ok = false;
  std::string error;         // what went wrong when !ok: one line
  double trace_seconds = 0;  // POV-Ray's CPU seconds of the trace, parsing excluded
  double parse_seconds = 0;  // its wall seconds of parsing, for the report
  std::uint64_t rays = 0;    // POV-Ray's count of rays, for comparison
};

// Whether a `povray` program is on the PATH.
bool povray_available();

PovRun run_povray(const std::string& pov_path, int width, int height);

}  // namespace bench
