// vmpray: render an NFF or built-in scene on the simulated VM_pRAY machine
// (default: the teapot on a 16-node hypercube, each node caching 1/8 of the
// database) or, with --single, in this process; write the image and report
// rays, page accesses and traffic, the network and per-node work (JSON with
// --stats). `vmpray sweep ...` runs the paper's experiments (app/experiments/sweep.hpp).
// Exit 0 on success, 2 for a bad command line (or an image too large for
// this machine's memory, found once the scene is read), 1 for a runtime
// error; errors are one line on stderr, and a failed run leaves no output file.
// The hidden --manpage and --completion bash print the manual page and the
// completion script the build installs (app/manual.hpp).
//
// Started by an MPI launcher (mpirun; vmpi::launched_by_mpi() reads its
// environment) with more than one rank, the machine is split over the
// ranks (app/render/ranks.hpp): rank 0 does all a one-process run does, the others
// run their nodes. Every rank parses the same command line, so a bad one
// fails on all alike and rank 0 alone says so; a failure on any rank after
// that ends every rank, and rank 0 prints its one line. With one rank, or
// without a launcher, vmpray runs in one process exactly as always.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/experiments/machine_pictures.hpp"
#include "app/experiments/network_study.hpp"
#include "app/experiments/output_check.hpp"
#include "app/experiments/replay.hpp"
#include "app/experiments/sweep.hpp"
#include "app/manual.hpp"
#include "app/render/machine_run.hpp"
#include "app/render/memory_check.hpp"
#include "app/render/options.hpp"
#include "app/render/output_files.hpp"
#include "app/render/ranks.hpp"
#include "app/render/run_report.hpp"
#include "app/render/scene_input.hpp"
#include "app/render/single_run.hpp"
#include "app/render/version.hpp"
#include "mpi/mpi_transport.hpp"
#include "tracer/database.hpp"

namespace {

app::PictureFiles picture_files(const app::Options& o) {
  return {o.pictures.machine_svg, o.pictures.ownership_png, o.pictures.report_html, o.pictures.timeline_svg};
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ignored;
  return std::filesystem::weakly_canonical(std::filesystem::absolute(a), ignored) ==
         std::filesystem::weakly_canonical(std::filesystem::absolute(b), ignored);
}

// Two outputs at one path would overwrite each other: refused before the render.
void check_distinct_outputs(const app::Options& o) {
  std::vector<std::pair<std::string, std::filesystem::path>> outputs{{"--output", o.output}};
  if (!o.stats_path.empty()) outputs.emplace_back("--stats", o.stats_path);
  if (!o.tiles_csv.empty()) outputs.emplace_back("--tiles", o.tiles_csv);
  if (!o.replay_html.empty()) outputs.emplace_back("--replay", o.replay_html);
  for (auto& output : app::picture_outputs(picture_files(o))) outputs.push_back(std::move(output));
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(outputs[i].second, outputs[j].second))
        throw app::UsageError(outputs[j].first + " and " + outputs[i].first + " would both write '" +
                              outputs[i].second.string() + "'");
}

// --estimate-memory: the estimate the checks before a run make, with the
// database built for its page count (the machine's tables follow it).
int print_memory_estimate(const app::Options& o, const tracer::Scene& scene) {
  std::uint32_t pages = 0;
  if (!o.single) pages = tracer::build_database(scene, app::build_options(o)).header.page_count;
  std::cout << app::describe_memory(o, scene.camera.width, scene.camera.height, pages, app::memory_limit());
  std::cout.flush();
  if (std::cout) return 0;
  std::cerr << "vmpray: cannot write to standard output\n";
  return 1;
}

// The whole run in this process, or rank 0's part over `ranks`.
int run(const app::Options& o, const std::vector<std::string>& command_line, nodes::Transport* ranks = nullptr) {
  tracer::Scene scene;
  double load_seconds = 0;
  try {
    app::check_output_paths(o);  // before the scene: a render is not done to be lost
    const auto t0 = std::chrono::steady_clock::now();
    scene = app::naming_memory_shortage("loading the scene", [&] { return app::load_scene(o); });
    load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.estimate_memory) return print_memory_estimate(o, scene);
    // Before the minutes of work that an image too large for the memory would waste.
    app::check_image_memory(o, scene, app::memory_limit());
  } catch (const std::exception& e) {
    if (ranks) nodes::abandon_machine(*ranks, e.what());  // they wait for their pages
    throw;
  }
  app::RenderResult result =
      o.single ? app::render_single(o, std::move(scene)) : app::render_machine(o, std::move(scene), ranks);
  result.report.load_seconds = load_seconds;
  result.report.version = VMPRAY_VERSION;
  result.report.command_line = command_line;
  app::OutputPhase phase;
  app::OutputFiles& outputs = phase.files();  // removed again if a later step fails
  outputs.write(o.output, [&](const auto& path) { result.image.write_image(path.string()); });
  // --stats - puts the JSON alone on standard output; the report people read goes to stderr.
  std::ostream& report_out = o.stats_path == "-" ? std::cerr : std::cout;
  if (o.stats_path == "-") std::cout << app::stats_json(result.report);
  else if (!o.stats_path.empty()) outputs.write_text(o.stats_path, app::stats_json(result.report));
  if (result.report.machine && !o.tiles_csv.empty())
    outputs.write_text(o.tiles_csv, app::tiles_csv(result.report.machine->report));
  if (result.report.machine && !o.replay_html.empty())
    outputs.write_text(o.replay_html, app::replay_page({.title = result.report.scene,
                                                        .made_by = "vmpray " VMPRAY_VERSION,
                                                        .command_line = command_line,
                                                        .report = &result.report.machine->report,
                                                        .image = &result.image}));
  if (result.report.machine)  // removes what it wrote if it fails; the image is written and not needed again
    for (const auto& path : app::write_machine_pictures(
             picture_files(o),
             {.title = result.report.scene, .version = "vmpray " VMPRAY_VERSION, .command_line = command_line},
             std::move(result.image), result.report.machine->report))
      outputs.add(path);
  // Printed once every file it names is written: a run stopped before then
  // (an error, a signal) leaves no line naming a file that is not there.
  if (!o.quiet) app::print_report(report_out, result.report);
  // Asked for by name, so printed even when --quiet.
  if (result.report.machine) app::print_routes(report_out, result.report.machine->report);
  return phase.finish(std::cout, "report");
}

// What --help, --version, --manpage or --completion print.
std::string text_for(app::Options::Action action) {
  switch (action) {
    case app::Options::Action::help: return app::usage_text();
    case app::Options::Action::manpage: return app::manual_page();
    case app::Options::Action::completion: return app::bash_completion();  // the one shell parse_options takes
    default: return app::version_text();
  }
}

// --help, --version, --manpage or --completion on standard output: 0, or 1
// with one line if it could not be written (a full device, a closed descriptor).
int print_help_or_version(const app::Options& options) {
  std::cout << text_for(options.action);
  std::cout.flush();
  if (std::cout) return 0;
  std::cerr << "vmpray: cannot write to standard output\n";
  return 1;
}

// One rank of several: see the opening comment.
int rank_main(int argc, char** argv, const vmpi::MpiSession& mpi) {
  const bool host = mpi.rank() == 0;
  const auto say = [host](const std::string& line) {
    if (host) std::cerr << "vmpray: " << line << "\n";
  };
  if (argc > 1 && std::string(argv[1]) == "sweep") {
    say("sweep runs its points in one process: run it without mpirun, or with -np 1");
    return 2;
  }
  app::Options options;
  try {
    options = app::parse_options(argc, argv);
    check_distinct_outputs(options);
    app::check_rank_options(options, mpi.size());
  } catch (const app::UsageError& e) {
    say(std::string(e.what()) + " (see vmpray --help)");
    return 2;
  }
  if (options.action != app::Options::Action::render) return host ? print_help_or_version(options) : 0;
  // --threads 0: the rank's share of the CPUs, then nodes::thread_count's choice.
  if (options.machine.threads.count == 0)
    options.machine.threads.cpus = app::threads_per_rank(0, mpi.ranks_on_this_host());
  const unsigned at_most = options.machine.threads.count ? options.machine.threads.count : options.machine.threads.cpus;
  options.machine.threads.shared_cores = app::cores_shared(at_most, mpi.ranks_on_this_host());
  try {
    vmpi::MpiTransport transport;
    if (host) return run(options, std::vector<std::string>(argv, argv + argc), &transport);
    app::serve_rank(options, transport);
    return 0;
  } catch (const nodes::RankFailure& e) {  // every rank knows: rank 0 says it
    say(e.what());
    return 1;
  } catch (const app::UsageError& e) {  // rank 0: an image too large, the others told
    say(e.what());
    return 2;
  } catch (const std::exception& e) {
    if (host) {
      say(e.what());
      return 1;
    }
    // What the wire could not carry: this rank ends the job itself.
    std::cerr << "vmpray: rank " << mpi.rank() << ": " << e.what() << "\n";
    vmpi::MpiSession::abort(1);
  }
}

int one_process(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "sweep") return app::sweep_main(argc - 1, argv + 1);
  if (argc > 1 && std::string(argv[1]) == "network") return app::network_main(argc - 1, argv + 1);
  app::Options options;
  try {
    options = app::parse_options(argc, argv);
    check_distinct_outputs(options);
  } catch (const app::UsageError& e) {
    std::cerr << "vmpray: " << e.what() << " (see vmpray --help)\n";
    return 2;
  }
  if (options.action != app::Options::Action::render) return print_help_or_version(options);
  try {
    return run(options, std::vector<std::string>(argv, argv + argc));
  } catch (const app::UsageError& e) {  // an image too large: no help to see
    std::cerr << "vmpray: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "vmpray: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<vmpi::MpiSession> mpi;
  if (vmpi::launched_by_mpi()) try {
      mpi.emplace(argc, argv);
    } catch (const std::exception& e) {
      std::cerr << "vmpray: " << e.what() << "\n";
      return 1;
    }
  if (mpi && mpi->size() > 1) return rank_main(argc, argv, *mpi);
  return one_process(argc, argv);
}
