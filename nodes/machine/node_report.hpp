// What one node, and one OS process of a machine split over several, did in
// a run: the parts of the machine's report (machine.hpp) that travel from
// rank to rank (report_wire.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "nodes/machine/page_server.hpp"
#include "nodes/machine/pixel_computer.hpp"
#include "nodes/machine/svm.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/ranks/bridge.hpp"

namespace nodes {

struct NodeReport {
  SvmStats svm;
  ServerCounters served;
  WorkerCounters work;          // summed over the node's workers; spans of all, worker by worker
  std::size_t own_bytes = 0;    // scene bytes the node owns
  std::size_t peak_resident_bytes = 0;  // own pages + cache slots ever used
  std::uint32_t cache_capacity = 0;     // pages
  std::uint64_t evictions = 0;          // cached pages dropped for others
};

// One OS process of a machine split over several (run_machine_rank).
struct RankReport {
  int rank = 0;
  NodeId first_node = 0;
  std::uint32_t node_count = 0;
  unsigned threads = 0;
  BridgeCounters bridge;            // what crossed the wire from and to this rank
  double wall_seconds = 0;          // its run, from its set-up to its end
  double cpu_seconds = 0;           // CPU time (user + system) its threads used meanwhile
  std::uint64_t peak_scene_bytes = 0;  // own pages + cache slots ever used, over its nodes
};

}  // namespace nodes
