// Machine rendering; see machine_run.hpp.
#include "app/render/machine_run.hpp"

#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "app/render/cpu_count.hpp"
#include "app/render/memory_check.hpp"
#include "app/render/progress.hpp"
#include "app/render/usage_error.hpp"

namespace app {
namespace {

// Runs db on the machine of `machine` (over the ranks of `ranks`, if
// given), with a progress bar over what it farms out: pixels, or the corner
// samples of the SPD procedure; `which` follows the unit in the bar.
nodes::MachineResult run_with_progress(tracer::Database db, nodes::MachineOptions machine, const Options& o,
                                       const std::string& which = "", nodes::Transport* ranks = nullptr) {
  const std::uint64_t w = db.header.camera.width, h = db.header.camera.height;
  const bool samples = machine.trace.spd_procedure;
  ProgressBar bar(samples ? (w + 1) * (h + 1) : w * h, (samples ? "samples" : "pixels") + which,
                  !o.quiet && stderr_is_terminal(), "render", STDERR_FILENO,
                  "starting the machine and handing out its " + std::to_string(db.header.page_count) + " pages");
  // The collector calls this on its own thread only, so the bar needs no lock.
  machine.progress = [&bar](std::uint64_t done, std::uint64_t) { bar.update(done); };
  // The machine's own thread count, which --threads asks for (at most one a node).
  const auto hinted = [](const nodes::ResourceError& e) {
    return with_hint(e, "--threads, " + std::to_string(e.threads()) + " here");
  };
  try {
    nodes::MachineResult result = ranks ? std::move(*nodes::run_machine_rank(std::move(db), machine, *ranks))
                                        : nodes::run_machine(std::move(db), machine);
    bar.finish();
    return result;
  } catch (const nodes::OptionError& e) {
    throw usage_error(e);
  } catch (const nodes::ResourceError& e) {
    throw std::runtime_error(hinted(e));
  } catch (const nodes::RankFailure& e) {
    if (!e.resource()) throw;
    throw nodes::RankFailure(e.rank(), hinted(*e.resource()));
  }
}

SerialComparison run_serial(const tracer::Database& db, const nodes::MachineOptions& machine,
                            const Options& o) {
  nodes::MachineOptions one = machine;
  one.topology = topology::Topology::complete(1);
  one.observe.trace_routes = 0;
  one.observe.record = false;
  const nodes::MachineResult r = run_with_progress(db, one, o, " (1 node)");
  return {machine.timing ? r.report.predicted_seconds : r.report.wall_seconds, r.report.threads};
}

}  // namespace

std::string with_hint(const nodes::ResourceError& error, const std::string& fewer_threads) {
  const std::string line = error.what();
  if (error.resource() == nodes::ResourceError::Resource::thread)
    return line + "; try fewer threads (" + fewer_threads + "), or see ulimit -v and ulimit -u";
  return line + "; a machine of " + std::to_string(error.nodes()) +
         " nodes needs more memory than this process may map (see ulimit -v)";
}

nodes::MachineOptions machine_options(const Options& o) {
  nodes::MachineOptions machine = o.machine;
  if (machine.threads.count == 0 && machine.threads.cpus == 0)
    machine.threads.cpus = usable_cpus();  // affinity and CPU quota
  machine.trace = {.max_depth = o.max_depth,
                   .spd_procedure = o.spd_procedure,
                   .shadow_rays_to_all_lights = o.shadow_rays_all};
  return machine;
}

namespace {

// An explicit --threads above the nodes a process runs is lowered to one
// thread a node, not refused: say so (on rank 0, which prints for all).
void note_threads_lowered(unsigned asked, const nodes::MachineReport& r) {
  bool lowered = r.ranks.empty() && asked > r.threads && r.threads == static_cast<unsigned>(r.nodes);
  for (const nodes::RankReport& rank : r.ranks) lowered = lowered || (asked > rank.threads && rank.threads == rank.node_count);
  if (lowered)
    std::cerr << "vmpray: --threads " << asked << " lowered to " << r.threads << ": no more threads than nodes\n";
}

}  // namespace

RenderResult render_machine(const Options& o, tracer::Scene scene, nodes::Transport* ranks) {
  const int width = scene.camera.width, height = scene.camera.height;
  tracer::Database db;
  RunReport report;
  try {
    db = in_phase("building the database", !o.quiet && stderr_is_terminal(), [&] {
      return naming_memory_shortage("building the database",
                                    [&] { return build_database(std::move(scene), build_options(o)); });
    });
    // Before the machine is built: a complete graph of thousands of nodes would
    // take minutes to set up before running out of memory.
    check_machine_memory(o, width, height, db.header.page_count, memory_limit());
    report = describe_run(o, db);
  } catch (const std::exception& e) {
    if (ranks) nodes::abandon_machine(*ranks, e.what());  // they wait for their pages
    throw;
  }
  const nodes::MachineOptions machine = machine_options(o);
  std::optional<SerialComparison> serial;
  // In virtual time T1 is cheap and deterministic: always there for speedup and efficiency.
  if (o.compare_serial || machine.timing) serial = run_serial(db, machine, o);
  nodes::MachineResult result = run_with_progress(std::move(db), machine, o, "", ranks);
  note_threads_lowered(o.machine.threads.count, result.report);
  report.rays = result.report.rays();
  report.render_seconds = result.report.wall_seconds;
  report.machine = MachineSummary{std::move(result.report), serial, o.spd_procedure};
  // The machine's image itself: the result holds no image of its own while the machine runs.
  return {std::move(result.image), std::move(report)};
}

}  // namespace app
