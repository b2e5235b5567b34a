// build_bench: seconds to build the scene database (triangulation, BVH with
// treelet layout, packing; tracer::build_database) for tetra:6 .. tetra:11,
// on 1 thread and on T threads side by side, and the speedup; beside them
// seconds / (n log2 n) for n triangles, so the growth of the build with the
// scene can be read down the column; and the part of it that builds the BVH
// (BuildStats::accel_seconds: split clipping, the tree, the treelet layout,
// leaf order) on both thread counts. The two thread counts build the same
// database (the bench checks the pages are equal). Last, the peak resident
// memory of generating the scene and building it on T threads, measured in
// a fresh process (build_bench --peak SPEC T), beside the database's packed
// size and their ratio.
//
// Every size builds REPEATS times on each thread count, the runs interleaved
// so that load from other work falls on both sides alike; a line gives the
// medians. A size is skipped, with a message, when the memory available is
// short of what it needs (tetra:11, 4.2 million triangles, a few GB).
//
// usage: build_bench [THREADS [REPEATS]]   default: 2 3
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "tracer/database.hpp"
#include "tracer/generators.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// MemAvailable from /proc/meminfo, in bytes (0 when it cannot be read).
double available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return 0;
}

struct Runs {
  std::vector<double> total, bvh;
};

void build(const tracer::Scene& scene, unsigned threads, tracer::Database& out, Runs& runs) {
  const auto t0 = Clock::now();
  out = tracer::build_database(scene, {.threads = threads});
  runs.total.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  runs.bvh.push_back(out.stats.accel_seconds);
}

// One scene generated and built in this process: "peak_kb packed_bytes".
int peak_once(const std::string& spec, unsigned threads) {
  const tracer::Database db = tracer::build_database(tracer::generate_scene(spec), {.threads = threads});
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%ld %llu\n", ru.ru_maxrss, static_cast<unsigned long long>(db.header.bytes()));
  return 0;
}

struct Peak {
  double resident_mb = 0, packed_mb = 0;
};

Peak peak_in_child(const std::string& spec, unsigned threads) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string cmd = "'" + self + "' --peak " + spec + " " + std::to_string(threads);
  FILE* p = popen(cmd.c_str(), "r");
  long kb = 0;
  unsigned long long bytes = 0;
  if (!p || std::fscanf(p, "%ld %llu", &kb, &bytes) != 2 || pclose(p) != 0)
    throw std::runtime_error("measuring the peak memory of " + spec + " in a child process failed");
  return {double(kb) / 1024.0, double(bytes) / (1024.0 * 1024.0)};
}

const char* const usage =
    "usage: build_bench [THREADS [REPEATS]]   (THREADS 1..1024, default 2; REPEATS 1..100, default 3)\n"
    "       build_bench --peak SCENE THREADS    (one build, as the bench's child process does it)\n";

int bench_build(const std::vector<std::string>& args) {
  if (!args.empty() && args[0] == "--peak") {
    if (args.size() != 3) throw bench::BadArgument{"--peak takes SCENE THREADS"};
    return peak_once(args[1], static_cast<unsigned>(bench::parse_int(args[2], 1, 1024, "THREADS")));
  }
  if (args.size() > 2) throw bench::BadArgument{"too many arguments"};
  const auto threads = args.size() > 0 ? static_cast<unsigned>(bench::parse_int(args[0], 1, 1024, "THREADS")) : 2u;
  const auto repeats = args.size() > 1 ? static_cast<int>(bench::parse_int(args[1], 1, 100, "REPEATS")) : 3;
  std::printf("build_database, BVH with treelet layout, page size 1024; median of %d runs\n", repeats);
  const std::string t = std::to_string(threads);
  std::printf("%-9s %10s %9s %9s %8s %14s   %9s %9s %8s   %9s %9s %6s\n", "scene", "triangles", "1 thread",
              (t + " threads").c_str(), "speedup", "s/(n log2 n)", "BVH 1", ("BVH " + t).c_str(), "speedup", "peak MB",
              "packed MB", "ratio");
  for (int size = 6; size <= 11; ++size) {
    const std::string spec = "tetra:" + std::to_string(size);
    // About 700 bytes a triangle at the peak: the scene, the flattened
    // primitives, the BVH build and the pages, the last database still held.
    const double need = 700.0 * std::pow(4.0, size);
    if (available_memory() < need) {
      std::printf("%-9s skipped: needs about %.1f GB, %.1f GB available\n", spec.c_str(), need / 1e9,
                  available_memory() / 1e9);
      continue;
    }
    tracer::Scene scene;
    try {
      scene = tracer::generate_scene(spec);
    } catch (const std::invalid_argument& e) {
      std::printf("%-9s skipped: %s\n", spec.c_str(), e.what());
      continue;
    }
    Runs one, many;
    tracer::Database a, b;
    for (int r = 0; r < repeats; ++r) {
      build(scene, 1, a, one);
      build(scene, threads, b, many);
    }
    const double n = static_cast<double>(a.header.primitive_count);
    const double t1 = median(one.total), tt = median(many.total), b1 = median(one.bvh), bt = median(many.bvh);
    const bool same = a.pages == b.pages;
    a = b = tracer::Database{};  // freed before the child process runs beside this one
    scene = tracer::Scene{};
    const Peak peak = peak_in_child(spec, threads);
    std::printf("%-9s %10.0f %8.3fs %8.3fs %7.2fx %14.3g   %8.3fs %8.3fs %7.2fx   %9.1f %9.1f %5.2fx%s\n", spec.c_str(),
                n, t1, tt, t1 / tt, t1 / (n * std::log2(n)), b1, bt, b1 / bt, peak.resident_mb, peak.packed_mb,
                peak.resident_mb / peak.packed_mb, same ? "" : "  DIFFERENT PAGES");
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return bench::run_main("build_bench", usage, argc, argv, bench_build); }
