// nff_bench: how fast the NFF reader reads a large scene, and in how much
// memory. It writes a generated scene (tetra:10 by default, about 92 MB of
// text) as NFF to a temporary folder, plain and gzip-compressed, then reads
// each file with tracer::load_nff_file, best of 3 by CPU time. Every read runs in a
// fresh process (this program again, with --read), so its peak resident
// memory (getrusage) is the read's own: the scene it keeps, plus whatever
// the reader holds of the file.
//
//   nff_bench [SCENE] [RUNS] [--keep]   (--keep: leave the files, and say where)
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <variant>

#include "examples/bench/bench_args.hpp"
#include "tracer/generators.hpp"
#include "tracer/nff.hpp"

namespace {

// The scene as NFF, numbers as %g (six significant digits, as SPD writes them).
template <class Put>
void write_nff(const tracer::Scene& s, Put&& put) {
  char line[256];
  const auto out = [&](const char* fmt, auto... args) {
    const int n = std::snprintf(line, sizeof line, fmt, args...);
    put(line, static_cast<std::size_t>(n));
  };
  const tracer::Camera& c = s.camera;
  out("v\nfrom %g %g %g\nat %g %g %g\nup %g %g %g\nangle %g\nhither %g\nresolution %d %d\n", c.from.x, c.from.y,
      c.from.z, c.at.x, c.at.y, c.at.z, c.up.x, c.up.y, c.up.z, c.angle_deg, c.hither, c.width, c.height);
  out("b %g %g %g\n", double(s.background.r), double(s.background.g), double(s.background.b));
  for (const tracer::Light& l : s.lights) out("l %g %g %g\n", l.position.x, l.position.y, l.position.z);
  std::size_t material = ~std::size_t{0};
  for (const tracer::Object& o : s.objects) {
    if (o.material != material) {
      material = o.material;
      const tracer::Material& m = s.materials[material];
      out("f %g %g %g %g %g %g %g %g\n", double(m.color.r), double(m.color.g), double(m.color.b), m.kd, m.ks, m.shine,
          m.transmittance, m.ior);
    }
    if (const auto* p = std::get_if<tracer::Polygon>(&o.shape)) {
      out("p %zu\n", p->vertices.size());
      for (const tracer::Vec3d& v : p->vertices) out("%g %g %g\n", v.x, v.y, v.z);
    } else if (const auto* sp = std::get_if<tracer::Sphere>(&o.shape)) {
      out("s %g %g %g %g\n", sp->center.x, sp->center.y, sp->center.z, sp->radius);
    }  // the generators' other shapes are not needed for the bench's scenes
  }
}

// One read in this process: "seconds cpu_seconds peak_kb objects".
int read_once(const char* path) {
  timespec c0, c1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  const auto t0 = std::chrono::steady_clock::now();
  const tracer::Scene scene = tracer::load_nff_file(path);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%.6f %.6f %ld %zu\n", wall, double(c1.tv_sec - c0.tv_sec) + 1e-9 * double(c1.tv_nsec - c0.tv_nsec),
              ru.ru_maxrss, scene.objects.size());
  return 0;
}

struct Read {
  double wall = 1e30, cpu = 1e30;
  long peak_kb = 0;
  std::size_t objects = 0;
};

Read read_in_child(const std::string& self, const std::string& path) {
  const std::string cmd = "'" + self + "' --read '" + path + "'";
  FILE* p = popen(cmd.c_str(), "r");
  Read r;
  if (!p || std::fscanf(p, "%lf %lf %ld %zu", &r.wall, &r.cpu, &r.peak_kb, &r.objects) != 4) {
    std::fprintf(stderr, "nff_bench: reading %s failed\n", path.c_str());
    std::exit(1);
  }
  if (pclose(p) != 0) std::exit(1);
  return r;
}

}  // namespace

const char* const usage =
    "usage: nff_bench [SCENE [RUNS [--keep]]]   (default tetra:10 3; RUNS 1..100)\n"
    "       nff_bench --read FILE               (one read, as the bench's child process does it)\n";

int bench_nff(const std::vector<std::string>& args) {
  if (!args.empty() && args[0] == "--read") {
    if (args.size() != 2) throw bench::BadArgument{"--read takes one FILE"};
    return read_once(args[1].c_str());
  }
  if (args.size() > 3 || (args.size() == 3 && args[2] != "--keep"))
    throw bench::BadArgument{"expected SCENE [RUNS [--keep]]"};
  const std::string spec = args.size() > 0 ? args[0] : "tetra:10";
  const int runs = args.size() > 1 ? static_cast<int>(bench::parse_int(args[1], 1, 100, "RUNS")) : 3;
  const bool keep = args.size() > 2;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  char tmpl[] = "/tmp/nff_bench.XXXXXX";
  if (!mkdtemp(tmpl)) return 1;
  const std::filesystem::path dir(tmpl);
  const std::string plain = (dir / "scene.nff").string(), gz = (dir / "scene.nff.gz").string();
  {
    const tracer::Scene scene = tracer::generate_scene(spec);
    FILE* f = std::fopen(plain.c_str(), "wb");
    gzFile z = gzopen(gz.c_str(), "wb6");
    if (!f || !z) return 1;
    write_nff(scene, [&](const char* s, std::size_t n) {
      std::fwrite(s, 1, n, f);
      gzwrite(z, s, static_cast<unsigned>(n));
    });
    std::fclose(f);
    gzclose(z);
  }
  const double plain_mb = double(std::filesystem::file_size(plain)) / 1e6;
  const double gz_mb = double(std::filesystem::file_size(gz)) / 1e6;
  std::printf("%s as NFF: %.1f MB, gzip %.1f MB; best of %d reads, each in a fresh process\n", spec.c_str(), plain_mb,
              gz_mb, runs);
  for (const auto& [name, path] : {std::pair{"plain", plain}, std::pair{"gzip ", gz}}) {
    Read best;
    for (int i = 0; i < runs; ++i) {
      const Read r = read_in_child(self, path);
      if (r.cpu < best.cpu) best = r;  // CPU time: other programs on the machine disturb it less
    }
    std::printf(
        "  %s  %.3f s CPU (%.3f s wall), %6.1f MB/s of NFF text per CPU second, peak resident %.0f MB, %zu objects\n",
        name, best.cpu, best.wall, plain_mb / best.cpu, double(best.peak_kb) / 1024.0, best.objects);
  }
  if (keep)
    std::printf("files kept in %s\n", dir.c_str());
  else
    std::filesystem::remove_all(dir);
  return 0;
}

int main(int argc, char** argv) { return bench::run_main("nff_bench", usage, argc, argv, bench_nff); }
