// vmpray over several processes: what a run started by an MPI launcher
// with more than one rank may ask for, and the part every rank but the
// host plays. Rank 0 (the host) reads the scene, builds the database and
// writes every output; the other ranks run their block of nodes
// (nodes::run_machine_rank) and print nothing unless the wire itself fails.
#pragma once

#include "app/render/options.hpp"
#include "nodes/ranks/transport.hpp"

namespace app {

// UsageError naming the option for what cannot run over `ranks` processes:
// --single, --compare-serial, --timing virtual, and more ranks than nodes.
void check_rank_options(const Options& options, int ranks);

// --threads 0 over several ranks: the CPUs the launcher bound this rank
// to, or, unbound, the CPUs this process may use shared among the ranks on
// this host; at least one.
unsigned threads_per_rank(unsigned threads, int ranks_on_this_host);

// Whether this rank's threads must share their cores with other ranks:
// more than its bound CPUs, or, unbound, the host's ranks' threads
// together more than the CPUs.
bool cores_shared(unsigned threads, int ranks_on_this_host);

// A rank other than 0: its nodes, until the machine ends. Throws
// nodes::RankFailure when any rank failed (rank 0 reports it).
void serve_rank(const Options& options, nodes::Transport& transport);

}  // namespace app
