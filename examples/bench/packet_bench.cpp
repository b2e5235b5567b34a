// packet_bench: what the machine's packets cost on one thread. For each case
// (a scene on a hypercube of N nodes, default caches: an eighth of the
// database per node), the plain renderer (vmpray --single --threads 1) and
// the machine (vmpray --threads 1) render the same frame, runs alternating;
// both are timed the same way: the CPU time of the process around the call
// that renders (the database built beforehand, the frame allocated inside
// on both sides; the machine's distribution of the pages included). From
// the medians it prints the ratio machine / plain and the machine's extra
// CPU time per page miss and per hop (all packets' hops), so any change to
// the packet path shows in those units. Every run's image is compared with
// the plain renderer's; a difference is reported and fails the bench.
//
// usage: packet_bench [REPEATS [SIZE [CASE...]]]
//   REPEATS 1..100 (default 5), SIZE 16..4096 (default 512),
//   CASE SCENE:NODES, e.g. rings4:16 (default rings4:16 rings4:64 teapot:16 teapot:256)
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "nodes/machine/machine.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"
#include "tracer/render.hpp"

namespace {

const char* const usage =
    "usage: packet_bench [REPEATS [SIZE [SCENE:NODES...]]]\n"
    "  REPEATS 1..100 (default 5), SIZE 16..4096 (default 512),\n"
    "  cases default to rings4:16 rings4:64 teapot:16 teapot:256\n";

using bench::BadArgument;
using bench::parse_int;

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

struct Case {
  std::string scene;
  int nodes = 16;
};

Case parse_case(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || colon == 0)
    throw BadArgument{"case: expected SCENE:NODES, got '" + text + "'"};
  return {text.substr(0, colon), static_cast<int>(parse_int(text.substr(colon + 1), 1, 4096, "NODES"))};
}

tracer::Database make_db(const std::string& spec, int size) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = size;
  scene.camera.height = size;
  return tracer::build_database(scene, {});
}

bool same(const tracer::Image& image, const std::vector<tracer::Color>& reference) {
  const auto& px = image.pixels();
  return px.size() == reference.size() &&
         std::memcmp(px.data(), reference.data(), px.size() * sizeof(tracer::Color)) == 0;
}

// One case: returns false if an image differed.
bool run_case(const Case& c, int size, int repeats) {
  const tracer::Database db = make_db(c.scene, size);
  std::vector<double> plain, machine;
  std::vector<tracer::Color> reference;
  std::uint64_t misses = 0, hops = 0, packets = 0;
  bool identical = true;
  for (int r = 0; r < repeats; ++r) {
    {
      tracer::RayStats stats;
      const double start = cpu_seconds();
      std::vector<tracer::Color> image = tracer::render_frame(db, {}, stats, 1);
      plain.push_back(cpu_seconds() - start);
      if (reference.empty()) reference = std::move(image);
    }
    {
      tracer::Database copy = db;  // run_machine takes the database; the copy is not timed
      nodes::MachineOptions options;
      options.topology = topology::parse_topology("hypercube", static_cast<std::size_t>(c.nodes));
      options.threads.count = 1;
      const double start = cpu_seconds();
      const nodes::MachineResult result = nodes::run_machine(std::move(copy), options);
      machine.push_back(cpu_seconds() - start);
      identical = identical && same(result.image, reference);
      misses = result.report.svm().misses;
      hops = result.report.network.hops.total_hops;
      packets = result.report.network.hops.packets;
    }
  }
  const double p = median(plain), m = median(machine);
  std::printf("%-8s %5d %8.3f %8.3f %6.2fx %9llu %9llu %9llu %10.2f %9.3f   %s\n", c.scene.c_str(), c.nodes, p, m,
              m / p, static_cast<unsigned long long>(misses), static_cast<unsigned long long>(packets),
              static_cast<unsigned long long>(hops), misses ? (m - p) / double(misses) * 1e6 : 0.0,
              hops ? (m - p) / double(hops) * 1e6 : 0.0, identical ? "identical" : "IMAGE DIFFERS");
  return identical;
}

int bench_packets(const std::vector<std::string>& args) {
  const int repeats = args.size() > 0 ? static_cast<int>(parse_int(args[0], 1, 100, "REPEATS")) : 5;
  const int size = args.size() > 1 ? static_cast<int>(parse_int(args[1], 16, 4096, "SIZE")) : 512;
  std::vector<Case> cases;
  for (std::size_t i = 2; i < args.size(); ++i) cases.push_back(parse_case(args[i]));
  if (cases.empty()) cases = {{"rings4", 16}, {"rings4", 64}, {"teapot", 16}, {"teapot", 256}};
  for (const Case& c : cases) tracer::generate_scene(c.scene);  // a bad scene name fails before any work
  std::printf("one thread, %dx%d, hypercube, default caches; CPU seconds, median of %d alternating runs\n", size,
              size, repeats);
  std::printf("%-8s %5s %8s %8s %7s %9s %9s %9s %10s %9s\n", "scene", "nodes", "plain", "machine", "ratio",
              "misses", "packets", "hops", "us/miss", "us/hop");
  bool ok = true;
  for (const Case& c : cases) ok = run_case(c, size, repeats) && ok;
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) { return bench::run_main("packet_bench", usage, argc, argv, bench_packets); }
