// The machine renderer of `vmpray`: build the paged database on the host,
// hand it to nodes::run_machine (which spreads the pages over the processors
// and farms out the pixels), and fill the run report with the machine's
// figures. With --compare-serial the 1-node machine renders the same
// database too, for speedup and efficiency. The image equals the one
// render_single makes from the same scene and options, bit for bit.
#pragma once

#include "app/options.hpp"
#include "app/single.hpp"
#include "tracer/scene.hpp"

namespace app {

// Throws tracer::DatabaseError, std::invalid_argument (a machine option) or
// std::runtime_error, each one line.
RenderResult render_machine(const Options& options, const tracer::Scene& scene);

}  // namespace app
