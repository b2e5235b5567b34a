// The paper's experiments as functions: one machine run in virtual time
// reduced to the figures the paper reports (synthesis time, speedup,
// efficiency, miss ratio, page communications), and the fit of the compute
// constant to a published time.
//
// Every point is a deterministic virtual-time run (nodes/timing.hpp), so a
// point's figures depend only on its inputs, and points may run side by
// side on several threads with the same results. Speedup and efficiency are
// against the same scene on one node under the same model: E = T1 / (N * TN).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "nodes/machine/machine.hpp"
#include "nodes/machine/timing.hpp"
#include "topology/topology.hpp"
#include "tracer/database.hpp"
#include "tracer/render.hpp"

namespace app {

// The paper's farming: dynamic, scanline, tiles of 4 pixels, each asked for
// when its processor is idle.
inline constexpr nodes::Farming paper_farming{
    .grain = 4, .prefetch = 0, .schedule = nodes::Schedule::dynamic, .pixel_order = nodes::PixelOrder::scanline};

struct ExperimentSetup {
  topology::Topology topology = topology::Topology::hypercube(0);  // one node
  std::optional<std::uint32_t> cache_pages;  // default: nodes::default_cache_pages
  nodes::Farming farming = paper_farming;
  nodes::CostModel model = nodes::ipsc2_profile();
  tracer::TraceOptions trace;
};

struct ExperimentPoint {
  std::string topology;      // canonical spec
  int nodes = 0;
  std::uint32_t cache_pages = 0;
  double predicted_seconds = 0;
  double wall_seconds = 0;
  double serial_seconds = 0;  // T1 under the same model (0 if not known)
  std::uint64_t rays = 0;
  std::uint64_t page_accesses = 0;
  std::uint64_t misses = 0;           // page requests sent
  double miss_ratio = 0;
  double pages_per_pixel = 0;         // distinct pages touched per sample, as in Table 1
  double mean_hops = 0;
  std::uint64_t messages = 0;

  double speedup() const { return predicted_seconds > 0 ? serial_seconds / predicted_seconds : 0; }
  double efficiency() const { return nodes > 0 ? speedup() / nodes : 0; }
};

// The machine a setup runs.
nodes::MachineOptions machine_options(const ExperimentSetup& setup);

// One run of db's frame under setup; db is copied (the machine consumes its copy).
ExperimentPoint run_point(const tracer::Database& db, const ExperimentSetup& setup);

// Called with each point's index in order, once it and every point before
// it have finished; one call at a time.
using PointDone = std::function<void(std::size_t index, const ExperimentPoint& point)>;

// The points of all setups, in their order, run on up to `jobs` threads at
// once (the caller's among them; jobs 0 is taken as 1). Setups are handed
// out in order, so when runs fail the one rethrown, after the runs under
// way have finished, is the first in setup order, as a one-by-one run would
// report; no setup after a failure is started, and `done` is not called for
// it or for any point after it.
std::vector<ExperimentPoint> run_points(const tracer::Database& db, const std::vector<ExperimentSetup>& setups,
                                        unsigned jobs, const PointDone& done = {});

// The unit that makes db's one-node run under `setup` (its model, tracing
// and grain; its node count is ignored) take `seconds`: compute time is
// proportional to unit and the one-node run has no remote pages, so two runs
// (a probe unit, and unit 0 for the message time) fix it; they run on up to
// `jobs` threads.
double fit_unit(const tracer::Database& db, const ExperimentSetup& setup, double seconds, unsigned jobs);

// "3h12mn2s" as in the paper's Table 2 (also "51mn32s", "4.2s" below a minute).
std::string paper_duration(double seconds);

}  // namespace app
