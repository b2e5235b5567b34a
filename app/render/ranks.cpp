// Options over several ranks, and a non-host rank's run; see ranks.hpp.
#include "app/render/ranks.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <thread>

#include "app/render/cpu_count.hpp"
#include "app/render/machine_run.hpp"
#include "topology/topology.hpp"

namespace app {

void check_rank_options(const Options& o, int ranks) {
  if (ranks <= 1) return;
  const std::string over = " cannot run over several processes (" + std::to_string(ranks) + " MPI ranks here)";
  if (o.single) throw UsageError("--single renders in one process: run it without mpirun");
  if (o.estimate_memory) throw UsageError("--estimate-memory" + over + ": run it without mpirun");
  if (o.compare_serial) throw UsageError("--compare-serial" + over + ": it runs the 1-node machine beside this one");
  if (o.machine.timing)
    throw UsageError("--timing virtual" + over + ": one virtual clock orders the whole machine");
  const std::size_t nodes = o.machine.topology.size();
  if (static_cast<std::size_t>(ranks) > nodes)
    throw UsageError(std::to_string(ranks) + " MPI ranks for a machine of " + std::to_string(nodes) +
                     (nodes == 1 ? " node" : " nodes") + ": every rank needs one; use more --nodes or fewer ranks");
}

namespace {

// The CPUs this rank may use, and whether the launcher bound it to them
// alone (a mask smaller than the host's) or left the host's to all ranks.
struct RankCpus {
  unsigned cpus;
  bool bound;
};

RankCpus rank_cpus() {
  const unsigned cpus = usable_cpus();
  return {cpus, cpus < std::max(1u, std::thread::hardware_concurrency())};
}

}  // namespace

unsigned threads_per_rank(unsigned threads, int ranks_on_this_host) {
  if (threads != 0) return threads;
  const RankCpus mine = rank_cpus();
  if (mine.bound) return mine.cpus;
  return std::max(1u, mine.cpus / static_cast<unsigned>(std::max(ranks_on_this_host, 1)));
}

bool cores_shared(unsigned threads, int ranks_on_this_host) {
  const RankCpus mine = rank_cpus();
  const std::uint64_t wanted = mine.bound ? threads : std::uint64_t{threads} * std::max(ranks_on_this_host, 1);
  return wanted > mine.cpus;
}

void serve_rank(const Options& options, nodes::Transport& transport) {
  nodes::run_machine_rank(std::nullopt, machine_options(options), transport);
}

}  // namespace app
