// machine_bench: wall time of the VM_pRAY machine (shared virtual memory,
// farming with the machine's defaults, hypercube network) against the same
// renderer over one shared in-memory database with plain std::threads
// pulling rows (the single-process renderer, vmpray --single), measured side
// by side on the same threads; and the speedup of T threads over 1.
// Each machine line on T threads is also run with packets between threads
// on plain channels rather than through the thread relays, and the 1- and
// T-thread lines with every router step taken by the router's own process
// (no steps in place: a fiber switch per hop).
// Then where the machine's time goes, on 16 nodes and T threads: the same
// run with the BVH's nodes in depth-first layout rather than in treelets,
// with the paper's ask-when-idle protocol (prefetch 0), with every cache
// holding the whole database (no page traffic), with tiles of 256 pixels
// (little farming traffic), and with other schedules and pixel orders, down
// to the paper's farming (dynamic, in scanline order), and recorded hop by
// hop for a replay.
//
// Every configuration runs REPEATS times, the runs of a comparison (the
// single process's among them) interleaved so that load from other work
// falls on both sides alike; a line gives the median and the fastest run,
// and ratios are of medians. Both sides are timed the same way: wall time
// around the call that renders, the database built beforehand; the
// machine's distribution of the pages, and a recorded run's merge of its
// recording, are inside the time, as the single process's frame is.
//
// usage: machine_bench [SCENE [SIZE [THREADS [REPEATS]]]]   default: teapot 512 2 5
//   SIZE 16..4096, THREADS 1..1024, REPEATS 1..100; a bad argument: usage, exit 2
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "nodes/machine/machine.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"
#include "tracer/render.hpp"

namespace {

using Clock = std::chrono::steady_clock;

tracer::Database make_db(const std::string& spec, int size, const tracer::BuildOptions& build = {}) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = size;
  scene.camera.height = size;
  return tracer::build_database(scene, build);
}

// The single-process renderer (vmpray --single --threads T): rows pulled
// from a shared counter by plain threads over one database in memory. The
// frame is allocated inside the timed part, as the machine allocates its own.
double shared_memory_seconds(const tracer::Database& db, unsigned threads, std::vector<tracer::Color>& image) {
  const auto start = Clock::now();
  tracer::RayStats stats;
  image = tracer::render_frame(db, {}, stats, threads);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Wall times of repeated runs of one configuration.
struct Times {
  std::vector<double> seconds;

  double median() const {
    std::vector<double> v = seconds;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
  }
  double fastest() const { return *std::min_element(seconds.begin(), seconds.end()); }
};

struct MachineRun {
  Times times;
  double miss_ratio = 0;
  bool same_image = true;  // every run's image equal to the reference
  std::string error;       // non-empty: a run failed

  bool ok() const { return error.empty() && !times.seconds.empty(); }
};

using Variant = std::function<void(nodes::MachineOptions&, const tracer::DatabaseHeader&)>;

// One more run of a configuration, added to `run`.
void run_machine_once(MachineRun& run, const std::string& spec, int size, int nodes, unsigned threads,
                      const std::vector<tracer::Color>& reference, const Variant& variant = {},
                      const tracer::BuildOptions& build = {}) {
  if (!run.error.empty()) return;
  try {
    auto db = make_db(spec, size, build);  // not timed, as for the single process
    nodes::MachineOptions options;
    options.topology = topology::parse_topology("hypercube", static_cast<std::size_t>(nodes));
    options.threads.count = threads;
    options.cache.pages = std::max<std::uint32_t>(1, db.header.page_count / 8);
    if (variant) variant(options, db.header);
    const auto start = Clock::now();
    const auto result = nodes::run_machine(std::move(db), options);
    run.times.seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    run.miss_ratio = result.report.svm().miss_ratio();
    const auto& px = result.image.pixels();
    run.same_image = run.same_image && px.size() == reference.size() &&
                     std::memcmp(px.data(), reference.data(), px.size() * sizeof(tracer::Color)) == 0;
  } catch (const std::exception& e) {
    run.error = e.what();
    run.error = run.error.substr(0, run.error.find('\n'));
  }
}

void print_run(const char* label, const MachineRun& r, double baseline) {
  if (!r.ok()) {
    std::printf("%-46s failed: %s\n", label, r.error.c_str());
    return;
  }
  std::printf("%-46s %6.3f s (fastest %6.3f)   ratio to single process %5.2fx   miss ratio %.4f   image %s\n", label,
              r.times.median(), r.times.fastest(), r.times.median() / baseline, r.miss_ratio,
              r.same_image ? "identical" : "DIFFERS");
}

const char* const usage =
    "usage: machine_bench [SCENE [SIZE [THREADS [REPEATS]]]]   default: teapot 512 2 5\n"
    "  SIZE 16..4096, THREADS 1..1024, REPEATS 1..100\n";

int bench_machine(const std::vector<std::string>& args) {
  if (args.size() > 4) throw bench::BadArgument{"too many arguments"};
  const std::string spec = args.size() > 0 ? args[0] : "teapot";
  const int size = args.size() > 1 ? static_cast<int>(bench::parse_int(args[1], 16, 4096, "SIZE")) : 512;
  const unsigned threads =
      args.size() > 2 ? static_cast<unsigned>(bench::parse_int(args[2], 1, 1024, "THREADS")) : 2u;
  const int repeats = args.size() > 3 ? static_cast<int>(bench::parse_int(args[3], 1, 100, "REPEATS")) : 5;
  const tracer::Database db = make_db(spec, size);  // an unknown scene fails here, before any run
  std::printf("scene %s at %dx%d, %u database pages of %u bytes, cache = 1/8 of the database per node, "
              "%d runs of each line: median (fastest)\n",
              spec.c_str(), size, size, db.header.page_count, db.header.page_size, repeats);

  std::vector<tracer::Color> image;
  Times shared1, shared_t;  // from the rounds of the node counts below, interleaved with the machine's
  shared_memory_seconds(db, threads, image);  // the reference image, and a warm start for both sides

  for (int nodes : {16, 64}) {
    MachineRun one, many, plain, one_routers, many_routers;
    const Variant no_relays = [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) {
      o.threads.relay_between = false;
    };
    const Variant no_steps_in_place = [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) {
      o.threads.forward_in_place = false;
    };
    for (int r = 0; r < repeats; ++r) {
      std::vector<tracer::Color> frame;
      shared1.seconds.push_back(shared_memory_seconds(db, 1, frame));
      run_machine_once(one, spec, size, nodes, 1, image);
      shared_t.seconds.push_back(shared_memory_seconds(db, threads, frame));
      run_machine_once(many, spec, size, nodes, threads, image);
      run_machine_once(plain, spec, size, nodes, threads, image, no_relays);
      run_machine_once(one_routers, spec, size, nodes, 1, image, no_steps_in_place);
      run_machine_once(many_routers, spec, size, nodes, threads, image, no_steps_in_place);
    }
    if (nodes == 16) {
      std::printf("single process, 1 thread                       %6.3f s (fastest %6.3f)\n", shared1.median(),
                  shared1.fastest());
      std::printf("single process, %u threads                      %6.3f s (fastest %6.3f)   speedup %.2fx\n",
                  threads, shared_t.median(), shared_t.fastest(), shared1.median() / shared_t.median());
    }
    const std::string l1 = "machine hypercube " + std::to_string(nodes) + ", 1 thread";
    const std::string lt = "machine hypercube " + std::to_string(nodes) + ", " + std::to_string(threads) + " threads";
    print_run(l1.c_str(), one, shared1.median());
    print_run(lt.c_str(), many, shared_t.median());
    const std::string lp = lt + ", no relays";
    print_run(lp.c_str(), plain, shared_t.median());
    const std::string l1r = l1 + ", no steps in place", ltr = lt + ", no steps in place";
    print_run(l1r.c_str(), one_routers, shared1.median());
    print_run(ltr.c_str(), many_routers, shared_t.median());
    if (one.ok() && many.ok())
      std::printf("  speedup of %u threads over 1: %.2fx (fastest runs %.2fx); without relays %.2fx; "
                  "with no steps in place %.2fx\n",
                  threads, one.times.median() / many.times.median(), one.times.fastest() / many.times.fastest(),
                  plain.ok() ? one.times.median() / plain.times.median() : 0.0,
                  one_routers.ok() && many_routers.ok() ? one_routers.times.median() / many_routers.times.median()
                                                        : 0.0);
  }

  std::printf("where the time goes: hypercube 16, %u threads, against the single process on %u threads\n", threads,
              threads);
  struct Line {
    const char* label;
    Variant machine;
    tracer::BuildOptions build = {};
  };
  const std::vector<Line> variants{
      {"  as above (affinity, hilbert, grain 64)", {}},
      {"  BVH nodes in depth-first layout", {}, {.bvh_layout = tracer::BvhLayout::depth_first}},
      {"  prefetch 0 (ask when idle)",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) { o.farming.prefetch = 0; }},
      {"  cache = whole database (first-touch misses)",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader& h) { o.cache.pages = h.page_count; }},
      {"  grain 256", [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) { o.farming.grain = 256; }},
      {"  dynamic schedule",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) { o.farming.schedule = nodes::Schedule::dynamic; }},
      {"  scanline order",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) {
         o.farming.pixel_order = nodes::PixelOrder::scanline;
       }},
      {"  dynamic schedule, scanline order (the paper)",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) {
         o.farming.schedule = nodes::Schedule::dynamic;
         o.farming.pixel_order = nodes::PixelOrder::scanline;
       }},
      {"  static schedule (no farming, no balancing)",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) {
         o.farming.schedule = nodes::Schedule::static_split;
       }},
      {"  recorded for a replay (--replay)",
       [](nodes::MachineOptions& o, const tracer::DatabaseHeader&) { o.observe.record = true; }},
  };
  std::vector<MachineRun> runs(variants.size());
  Times baseline;  // the single process on T threads, in the same rounds
  for (int r = 0; r < repeats; ++r) {
    std::vector<tracer::Color> frame;
    baseline.seconds.push_back(shared_memory_seconds(db, threads, frame));
    for (std::size_t v = 0; v < variants.size(); ++v)
      run_machine_once(runs[v], spec, size, 16, threads, image, variants[v].machine, variants[v].build);
  }
  std::printf("  single process, %u threads, in these rounds   %6.3f s (fastest %6.3f)\n", threads, baseline.median(),
              baseline.fastest());
  for (std::size_t v = 0; v < variants.size(); ++v) print_run(variants[v].label, runs[v], baseline.median());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return bench::run_main("machine_bench", usage, argc, argv, bench_machine); }
