// Single experiment points and the compute-constant fit (see experiments.hpp).
#include "app/experiments.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace app {

ExperimentPoint run_point(const tracer::Database& db, const ExperimentSetup& setup) {
  nodes::MachineOptions options;
  options.topology = setup.topology;
  options.nodes = setup.nodes;
  options.cache_pages = setup.cache_pages;
  options.grain = setup.grain;
  options.prefetch = setup.prefetch;
  options.schedule = setup.schedule;
  options.pixel_order = setup.pixel_order;
  options.timing = setup.model;
  options.trace = setup.trace;
  const nodes::MachineResult result = nodes::run_machine(db, options);
  const nodes::MachineReport& r = result.report;
  ExperimentPoint p;
  p.topology = r.topology;
  p.nodes = r.nodes;
  p.cache_pages = r.cache_pages;
  p.predicted_seconds = r.predicted_seconds;
  p.wall_seconds = r.wall_seconds;
  const tracer::RayStats rays = r.rays();
  const nodes::SvmStats svm = r.svm();
  p.rays = rays.rays();
  p.page_accesses = svm.accesses();
  p.misses = svm.misses;
  p.miss_ratio = svm.miss_ratio();
  p.pages_per_pixel = rays.pages_per_sample();
  p.mean_hops = r.network.hops.mean();
  p.messages = r.network.hops.packets;
  return p;
}

double fit_unit(const tracer::Database& db, const ExperimentSetup& setup, double seconds) {
  if (!(seconds > 0)) throw std::invalid_argument("--fit-seconds must be positive");
  // A small probe unit keeps the probe run well inside the virtual clock's range.
  constexpr double probe_unit = 1e-6;
  ExperimentSetup probe = setup;
  probe.topology = "hypercube";
  probe.nodes = 1;
  probe.model.unit = probe_unit;
  const double compute = run_point(db, probe).predicted_seconds;
  probe.model.unit = 0.0;  // what remains is message time (work requests, results)
  const double messages = run_point(db, probe).predicted_seconds;
  if (compute - messages <= 0) throw std::runtime_error("fit: the one-node run did no counted work");
  return probe_unit * (seconds - messages) / (compute - messages);
}

std::string paper_duration(double seconds) {
  char text[64];
  if (seconds < 60) {
    std::snprintf(text, sizeof text, "%.1fs", seconds);
    return text;
  }
  const auto total = static_cast<long long>(std::llround(seconds));
  const long long h = total / 3600, m = total % 3600 / 60, s = total % 60;
  if (h > 0) std::snprintf(text, sizeof text, "%lldh%02lldmn%02llds", h, m, s);
  else std::snprintf(text, sizeof text, "%lldmn%02llds", m, s);
  return text;
}

}  // namespace app
