// The machine part of the run report, as in the paper: page accesses and the
// miss ratio, page communications, pages per pixel, per-node work and its
// imbalance, the network's messages and hops, wall time, and speedup and
// efficiency against the 1-node machine when that was run too.
// Printed for people and written as a JSON object (same fields) for scripts;
// the tiles, when recorded, as a CSV timeline.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "csp/runtime.hpp"
#include "nodes/machine/machine.hpp"

namespace app {

// Objects keep their keys in the order written, as people read them.
using Json = nlohmann::ordered_json;

// The 1-node machine on the same scene, for speedup T1/TN and efficiency T1/(N*TN).
// seconds: wall time, or the predicted (virtual) time when the run has a cost model.
struct SerialComparison {
  double seconds = 0;
  unsigned threads = 0;
};

struct MachineSummary {
  nodes::MachineReport report;
  std::optional<SerialComparison> serial;
  bool corner_samples = false;  // the items are SPD corner samples, not pixels

  // TN: the predicted time under a cost model, the wall time otherwise (as T1).
  double parallel_seconds() const;
  double speedup() const;
  double efficiency() const;
};

void print_machine_report(std::ostream& out, const MachineSummary& m);

// When the machine's threads had a core for less than 90% of the time they
// ran processes or spun for work (summed over the threads: their CPU time
// over their running and spinning time), something else took the cores:
// more threads than the `cpus` the process may use, other programs, or
// (`over_ranks`) ranks beyond the cores. A line saying which, and that
// fewer threads or ranks may be faster, since a machine's threads wait on
// each other. "" for one thread.
std::string busy_cores_note(const std::vector<csp::ThreadUse>& threads, bool over_ranks, unsigned cpus);

// The routes --trace-routes recorded, under a heading, one packet a line
// ("  page_request 17: 5 → 4 → 6 (2 hops)"); nothing when none were traced.
void print_routes(std::ostream& out, const nodes::MachineReport& report);

// The run's tiles (recorded with MachineOptions::record_tiles) as CSV, one
// row per tile in order of start time (ties by node, worker): node, worker,
// first_item, items, start_s, end_s, page_requests, rays. Items are numbered
// in the run's pixel order.
std::string tiles_csv(const nodes::MachineReport& report);
// The machine's part of the --stats document, the same fields as the summary.
Json machine_json(const MachineSummary& m);

// The block of nodes a rank runs, "first-last", as the text and the page show it.
std::string rank_nodes(const nodes::RankReport& rank);
// A virtual-time cost model as an object: its name and every constant
// (seconds, and link bytes per second), then its one-line description.
Json cost_model_json(const nodes::CostModel& model);

}  // namespace app
