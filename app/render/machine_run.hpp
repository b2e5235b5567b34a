// The machine renderer of `vmpray`: build the paged database on the host,
// hand it to nodes::run_machine (which spreads the pages over the processors
// and farms out the pixels), and fill the run report with the machine's
// figures. With --compare-serial the 1-node machine renders the same
// database too, for speedup and efficiency (not over several ranks). The image equals the one
// render_single makes from the same scene and options, bit for bit.
#pragma once

#include "app/render/options.hpp"
#include "app/render/single_run.hpp"
#include "tracer/scene.hpp"

namespace app {

// The machine's options from the command line's, with the tracing options.
nodes::MachineOptions machine_options(const Options& options);

// A machine the system could not give memory or threads: its line and what
// to change. `fewer_threads` says how to ask for fewer ("--threads, 8 here").
std::string with_hint(const nodes::ResourceError& error, const std::string& fewer_threads);

// Throws tracer::DatabaseError, UsageError (a machine option),
// nodes::RankFailure or std::runtime_error, each one line; a shortage of
// memory or threads comes with its hint. With `ranks`, this process is rank 0
// of a machine split over them (nodes::run_machine_rank); every other rank
// runs nodes::run_machine_rank with machine_options(options) meanwhile.
// The scene is consumed by the build (tracer::build_database).
RenderResult render_machine(const Options& options, tracer::Scene scene, nodes::Transport* ranks = nullptr);

}  // namespace app
