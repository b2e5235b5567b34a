// Single experiment points and the compute-constant fit (see points.hpp).
#include "app/experiments/points.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace app {

nodes::MachineOptions machine_options(const ExperimentSetup& setup) {
  nodes::MachineOptions options;
  options.topology = setup.topology;
  options.cache.pages = setup.cache_pages;
  options.farming = setup.farming;
  options.timing = setup.model;
  options.trace = setup.trace;
  return options;
}

ExperimentPoint run_point(const tracer::Database& db, const ExperimentSetup& setup) {
  const nodes::MachineResult result = nodes::run_machine(db, machine_options(setup));
  const nodes::MachineReport& r = result.report;
  ExperimentPoint p;
  p.topology = r.topology.spec();
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

std::vector<ExperimentPoint> run_points(const tracer::Database& db, const std::vector<ExperimentSetup>& setups,
                                        unsigned jobs, const PointDone& done) {
  const std::size_t count = setups.size();
  std::vector<ExperimentPoint> points(count);
  std::vector<std::exception_ptr> failures(count);
  std::vector<bool> finished(count, false);
  std::mutex lock;  // guards everything below, and the calls of `done`
  std::size_t next = 0, reported = 0;
  bool failed = false;
  const auto work = [&] {
    for (;;) {
      std::size_t i = 0;
      {
        const std::lock_guard held(lock);
        if (failed || next == count) return;
        i = next++;
      }
      try {
        points[i] = run_point(db, setups[i]);
      } catch (...) {
        failures[i] = std::current_exception();
      }
      const std::lock_guard held(lock);
      finished[i] = true;
      if (failures[i]) failed = true;
      for (; reported < count && finished[reported] && !failures[reported]; ++reported) {
        if (!done) continue;
        try {
          done(reported, points[reported]);
        } catch (...) {
          failures[reported] = std::current_exception();
          failed = true;
          break;
        }
      }
    }
  };
  std::vector<std::thread> helpers;
  const std::size_t wanted = std::min<std::size_t>(std::max(jobs, 1u), count);
  for (std::size_t k = 1; k < wanted; ++k) {
    try {
      helpers.emplace_back(work);
    } catch (...) {  // no thread or no memory for one: fewer jobs
      break;         // the threads that did start, and this one, run every point
    }
  }
  work();
  for (std::thread& t : helpers) t.join();
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);
  return points;
}

double fit_unit(const tracer::Database& db, const ExperimentSetup& setup, double seconds, unsigned jobs) {
  if (!(seconds > 0)) throw std::invalid_argument("--fit-seconds must be positive");
  // A small probe unit keeps the probe run well inside the virtual clock's range.
  constexpr double probe_unit = 1e-6;
  ExperimentSetup probe = setup;
  probe.topology = topology::Topology::hypercube(0);
  probe.model.unit = probe_unit;
  ExperimentSetup messages_only = probe;
  messages_only.model.unit = 0.0;  // what remains is message time (work requests, results)
  const std::vector<ExperimentPoint> runs = run_points(db, {probe, messages_only}, jobs);
  const double compute = runs[0].predicted_seconds, messages = runs[1].predicted_seconds;
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
