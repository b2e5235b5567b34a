// The single-process renderer: build the paged database, trace every pixel
// through an InMemoryPageSource, and fill the report. A distributed machine
// renders the same scene and options to the same image.
#pragma once

#include "app/render/options.hpp"
#include "app/render/run_report.hpp"
#include "tracer/image.hpp"
#include "tracer/scene.hpp"

namespace app {

struct RenderResult {
  tracer::Image image;
  RunReport report;
};

// Throws tracer::DatabaseError or std::runtime_error (one line) on bad input.
// The scene is consumed by the build (tracer::build_database).
RenderResult render_single(const Options& options, tracer::Scene scene);

// The report fields that come from the scene, the options and the database.
RunReport describe_run(const Options& options, const tracer::Database& db);

}  // namespace app
