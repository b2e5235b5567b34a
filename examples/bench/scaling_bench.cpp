// scaling_bench: the machine and the plain renderer (vmpray --single) on 1
// to N threads, per case SCENE:NODES (a hypercube, the render's defaults:
// caches of an eighth of the database, affinity schedule, prefetch 1), and
// the default thread count (threads 0, nodes::thread_count) beside the
// fastest. For the largest thread count, how the machine's threads spent the
// run (running, spinning, sleeping: shares of their wall time) and the
// packets that crossed threads per packet delivered. When THREADS holds 1
// and 2, each case's time on every count is also predicted by the model of
// T threads (nodes::ThreadModel), fitted to the runs on 1 and 2 threads and
// to two nodes of the same scene and caches on 1 and 2 threads, and put
// beside the measured time.
//
// Every figure is the median of REPEATS wall times around the call that
// renders (database built beforehand, on both sides). Each round runs every
// case at every thread count, plain renderer then machine, so load from
// other work falls on all alike. Every image is compared with the plain
// renderer's; a difference is printed and makes the exit status 1.
//
// usage: scaling_bench [CASES [THREADS [SIZE [REPEATS]]]]
//   CASES: SCENE:NODES[:wWORKERS][:cCACHE_PAGES][:a0|:a1][:s], e.g. rings4:64:c64
//   default: rings4:16,rings4:64,teapot:16,teapot:64 1,2,4,8,16 512 3
//   THREADS: increasing counts, 1..1024 (more than the cores oversubscribes
//   them); SIZE 16..4096; REPEATS 1..100; a bad argument: usage, exit 2
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "examples/bench/bench_args.hpp"
#include "nodes/machine/machine.hpp"
#include "nodes/machine/thread_model.hpp"
#include "topology/spec.hpp"
#include "tracer/generators.hpp"
#include "tracer/render.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Case {
  std::string label;  // as given
  std::string scene;
  int nodes = 16;
  int workers = 1;                          // :wW
  std::optional<std::uint32_t> cache_pages;  // :cC; none: the default
  std::optional<bool> answer_at_once;       // :a1 or :a0; none: the machine's rule (nodes::answers_at_once)
  bool signal = false;                      // :s, the relays signal each batch (MachineOptions::threads.poll_rings off)
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ',');) parts.push_back(item);
  return parts;
}

// SCENE:NODES[:wWORKERS][:cCACHE_PAGES][:a0|:a1][:s]; a scene spec may hold
// colons of its own, so the fields are taken from the end.
Case parse_case(const std::string& item) {
  Case c;
  c.label = item;
  std::string rest = item;
  for (;;) {
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos || colon == 0)
      throw bench::BadArgument{"CASES: expected SCENE:NODES[:wWORKERS][:cCACHE_PAGES][:a0|:a1][:s], got '" + item +
                               "'"};
    const std::string field = rest.substr(colon + 1);
    rest.resize(colon);
    if (!field.empty() && field[0] == 'w') {
      c.workers = static_cast<int>(bench::parse_int(field.substr(1), 1, 64, "CASES' WORKERS"));
    } else if (field == "a0" || field == "a1") {
      c.answer_at_once = field == "a1";
    } else if (field == "s") {
      c.signal = true;
    } else if (!field.empty() && field[0] == 'c') {
      c.cache_pages = static_cast<std::uint32_t>(bench::parse_int(field.substr(1), 1, 1 << 24, "CASES' CACHE_PAGES"));
    } else {
      c.nodes = static_cast<int>(bench::parse_int(field, 1, 4096, "CASES' NODES"));
      break;
    }
  }
  if (c.nodes & (c.nodes - 1))
    throw bench::BadArgument{"CASES: a hypercube needs a power-of-two node count, got '" + item + "'"};
  c.scene = rest;
  return c;
}

std::vector<Case> parse_cases(const std::string& text) {
  std::vector<Case> cases;
  for (const std::string& item : split(text)) cases.push_back(parse_case(item));
  if (cases.empty()) throw bench::BadArgument{"CASES: empty list"};
  return cases;
}

std::vector<unsigned> parse_threads(const std::string& text) {
  std::vector<unsigned> threads;
  for (const std::string& item : split(text)) {
    const auto t = static_cast<unsigned>(bench::parse_int(item, 1, 1024, "THREADS"));
    if (!threads.empty() && t <= threads.back()) throw bench::BadArgument{"THREADS: expected increasing counts"};
    threads.push_back(t);
  }
  if (threads.empty()) throw bench::BadArgument{"THREADS: empty list"};
  return threads;
}

tracer::Database make_db(const std::string& spec, int size) {
  tracer::Scene scene = tracer::generate_scene(spec);
  scene.camera.width = size;
  scene.camera.height = size;
  return tracer::build_database(scene);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

bool same(const std::vector<tracer::Color>& a, const std::vector<tracer::Color>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(tracer::Color)) == 0;
}

// What one machine run leaves for the table: its time, and for the shares
// and crossings, its report's sums.
struct MachineSample {
  double seconds = 0;
  double running = 0, spinning = 0, sleeping = 0, wall = 0;  // summed over threads
  std::uint64_t crossings = 0, packets = 0;
  std::uint64_t misses = 0;  // page requests sent: the same on any thread count
  unsigned threads = 0;
};

MachineSample run_machine(const Case& c, const tracer::Database& source, unsigned threads,
                          const std::vector<tracer::Color>& reference, bool& differs) {
  tracer::Database db = source;  // copied outside the timed part, as the plain side's is built
  nodes::MachineOptions options;
  options.topology = topology::parse_topology("hypercube", static_cast<std::size_t>(c.nodes));
  options.threads.count = threads;  // 0: the default rule
  options.shape.workers_per_node = c.workers;
  if (c.cache_pages) options.cache.pages = c.cache_pages;
  options.threads.answer_at_once = c.answer_at_once;
  options.threads.poll_rings = !c.signal;
  const auto start = Clock::now();
  const nodes::MachineResult result = nodes::run_machine(std::move(db), options);
  MachineSample s;
  s.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  s.threads = result.report.threads;
  for (const csp::ThreadUse& u : result.report.host_threads) {
    s.running += u.running_seconds;
    s.spinning += u.spinning_seconds;
    s.sleeping += u.sleeping_seconds;
    s.wall += u.seconds;
  }
  for (const nodes::RelayCounters& r : result.report.relays) s.crossings += r.packets_sent;
  s.packets = result.report.network.hops.packets;
  s.misses = result.report.svm().misses;
  if (!same(result.image.pixels(), reference)) differs = true;
  return s;
}

double plain_seconds(const tracer::Database& db, unsigned threads, std::vector<tracer::Color>& image) {
  const auto start = Clock::now();
  tracer::RayStats stats;
  image = tracer::render_frame(db, {}, stats, threads);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Row {
  std::map<unsigned, std::vector<double>> machine, plain;  // by threads; 0: the default
  std::vector<MachineSample> widest;                      // the machine's runs on the most threads
  unsigned default_threads = 0;
  std::uint64_t misses = 0;
  bool differs = false;
};

// Two nodes of a case's scene and caches, one pixel computer each, on one
// thread and on two: what the model's latency is fitted to.
struct LatencyRuns {
  std::vector<double> one, two;
  std::uint64_t misses = 0;
};

Case latency_case(const Case& c) {
  Case f = c;
  f.nodes = 2;
  f.workers = 1;
  return f;
}

std::string latency_key(const Case& c) {
  return c.scene + (c.cache_pages ? ":c" + std::to_string(*c.cache_pages) : std::string()) +
         (c.answer_at_once ? (*c.answer_at_once ? ":a1" : ":a0") : "") + (c.signal ? ":s" : "");
}

// The model fitted to a row's runs on 1 and 2 threads and its scene's two
// nodes, its prediction for every thread count, and measured over predicted.
// The summary of examples/bench/many_cores.sh reads the last line's
// THREADS:RATIO fields.
void print_model(const Case& c, const Row& row, const LatencyRuns& fit, const std::vector<unsigned>& threads) {
  nodes::ThreadModel model;
  model.work_seconds = median(row.machine.at(1));
  model.misses = static_cast<double>(row.misses);
  model.pixel_computers = static_cast<double>(c.nodes) * c.workers;
  model.crossing_seconds =
      nodes::ThreadModel::fit_crossing(model.work_seconds, median(row.machine.at(2)), model.misses);
  model.latency_seconds = nodes::ThreadModel::fit_latency(median(fit.one), median(fit.two),
                                                          static_cast<double>(fit.misses), model.crossing_seconds);
  std::printf("%-12s model  ", "");
  for (const unsigned t : threads) std::printf(" %8.3f", model.predict(t));
  std::printf("   c %.2f us a crossing, L %.1f us (2 nodes: %.3f s on 1 thread, %.3f s on 2), %llu misses\n",
              1e6 * model.crossing_seconds, 1e6 * model.latency_seconds, median(fit.one), median(fit.two),
              static_cast<unsigned long long>(row.misses));
  std::printf("%-12s measured / model", "");
  for (const unsigned t : threads) std::printf(" %u:%.2fx", t, median(row.machine.at(t)) / model.predict(t));
  std::printf("\n");
}

void print_row(const Case& c, const Row& row, const std::vector<unsigned>& threads) {
  const double one = median(row.machine.at(threads.front()));
  double best = one;
  unsigned best_t = threads.front();
  std::printf("%-12s machine", c.label.c_str());
  for (const unsigned t : threads) {
    const double m = median(row.machine.at(t));
    std::printf(" %8.3f", m);
    if (m < best) best = m, best_t = t;
  }
  const double def = median(row.machine.at(0));
  std::printf("   best %.2fx at %u; default (%u threads) %.3f s, %.2fx the fastest\n", one / best, best_t,
              row.default_threads, def, def / best);
  std::printf("%-12s plain  ", "");
  for (const unsigned t : threads) std::printf(" %8.3f", median(row.plain.at(t)));
  std::printf("   best %.2fx\n", median(row.plain.at(threads.front())) /
                                     median(row.plain.at(threads.back())));
  std::printf("%-12s machine / plain", "");
  for (const unsigned t : threads) std::printf(" %.2fx", median(row.machine.at(t)) / median(row.plain.at(t)));
  MachineSample sum;
  for (const MachineSample& s : row.widest) {
    sum.running += s.running, sum.spinning += s.spinning, sum.sleeping += s.sleeping, sum.wall += s.wall;
    sum.crossings += s.crossings, sum.packets += s.packets;
  }
  const double wall = sum.wall > 0 ? sum.wall : 1;
  std::printf("\n%-12s on %u threads: running %.0f%%, spinning %.0f%%, sleeping %.0f%%; %.2f crossings per packet%s\n",
              "", threads.back(), 100 * sum.running / wall, 100 * sum.spinning / wall, 100 * sum.sleeping / wall,
              sum.packets ? static_cast<double>(sum.crossings) / static_cast<double>(sum.packets) : 0.0,
              row.differs ? "   IMAGE DIFFERS" : "");
}

const char* const usage =
    "usage: scaling_bench [CASES [THREADS [SIZE [REPEATS]]]]\n"
    "  default: rings4:16,rings4:64,teapot:16,teapot:64 1,2,4,8,16 512 3\n"
    "  CASES: SCENE:NODES[:wWORKERS][:cCACHE_PAGES][:a0|:a1][:s], comma-separated (a hypercube of NODES, a\n"
    "  power of two; WORKERS pixel computers a node, 1..64; CACHE_PAGES a node, default 1/8 of the\n"
    "  database; a1 or a0: pixel computers answer a packet for their thread at once, or not, whatever\n"
    "  the machine's rule says; s: the thread relays signal each batch instead of the threads polling\n"
    "  their rings)\n"
    "  THREADS: increasing, 1..1024; SIZE 16..4096; REPEATS 1..100\n"
    "  THREADS starting 1,2: each case's time predicted by the model of T threads, beside it\n";

int bench_scaling(const std::vector<std::string>& args) {
  if (args.size() > 4) throw bench::BadArgument{"too many arguments"};
  const std::vector<Case> cases = parse_cases(args.size() > 0 ? args[0] : "rings4:16,rings4:64,teapot:16,teapot:64");
  const std::vector<unsigned> threads = parse_threads(args.size() > 1 ? args[1] : "1,2,4,8,16");
  const int size = args.size() > 2 ? static_cast<int>(bench::parse_int(args[2], 16, 4096, "SIZE")) : 512;
  const int repeats = args.size() > 3 ? static_cast<int>(bench::parse_int(args[3], 1, 100, "REPEATS")) : 3;
  std::map<std::string, tracer::Database> dbs;
  std::map<std::string, std::vector<tracer::Color>> reference;
  bool any_differs = false;
  for (const Case& c : cases) {
    if (dbs.count(c.scene)) continue;
    dbs.emplace(c.scene, make_db(c.scene, size));  // an unknown scene fails here, before any run
    plain_seconds(dbs.at(c.scene), 1, reference[c.scene]);
  }
  std::printf("%dx%d, hypercubes, the render's defaults, %u CPUs here; median of %d wall times (s) per thread count:",
              size, size, std::max(1u, std::thread::hardware_concurrency()), repeats);
  for (const unsigned t : threads) std::printf(" %u", t);
  std::printf("\n");
  std::vector<Row> rows(cases.size());
  const bool modelled = threads.size() >= 2 && threads[0] == 1 && threads[1] == 2;
  std::map<std::string, LatencyRuns> fits;  // by latency_key
  for (int r = 0; r < repeats; ++r) {
    if (modelled)
      for (const Case& c : cases) {
        LatencyRuns& fit = fits[latency_key(c)];
        if (fit.one.size() > static_cast<std::size_t>(r)) continue;  // a case of the same scene and caches did it
        const Case f = latency_case(c);
        const tracer::Database& db = dbs.at(c.scene);
        bool differs = false;
        const MachineSample one = run_machine(f, db, 1, reference.at(c.scene), differs);
        fit.one.push_back(one.seconds);
        fit.two.push_back(run_machine(f, db, 2, reference.at(c.scene), differs).seconds);
        fit.misses = one.misses;
        if (differs) {
          std::printf("%s on 2 nodes: IMAGE DIFFERS\n", c.label.c_str());
          any_differs = true;
        }
      }
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Case& c = cases[i];
      const tracer::Database& db = dbs.at(c.scene);
      std::vector<tracer::Color> image;
      for (const unsigned t : threads) {
        rows[i].plain[t].push_back(plain_seconds(db, t, image));
        rows[i].differs = rows[i].differs || !same(image, reference.at(c.scene));
        const MachineSample s = run_machine(c, db, t, reference.at(c.scene), rows[i].differs);
        rows[i].machine[t].push_back(s.seconds);
        rows[i].misses = s.misses;
        if (t == threads.back()) rows[i].widest.push_back(s);
      }
      const MachineSample d = run_machine(c, db, 0, reference.at(c.scene), rows[i].differs);
      rows[i].machine[0].push_back(d.seconds);
      rows[i].default_threads = d.threads;
    }
  }
  for (std::size_t i = 0; i < cases.size(); ++i) {
    print_row(cases[i], rows[i], threads);
    if (modelled) print_model(cases[i], rows[i], fits.at(latency_key(cases[i])), threads);
    any_differs = any_differs || rows[i].differs;
  }
  return any_differs ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) { return bench::run_main("scaling_bench", usage, argc, argv, bench_scaling); }
