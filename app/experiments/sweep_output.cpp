// What a sweep writes: CSV and JSON tables, the plots (SVG, one PNG per
// panel), the HTML page, and the subcommand's entry point (see sweep.hpp).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "app/experiments/paper_figures.hpp"
#include "app/experiments/sweep.hpp"
#include "app/render/machine_run.hpp"
#include "app/render/options.hpp"
#include "app/render/output_files.hpp"
#include "app/render/run_report.hpp"
#include "app/viz/html_report.hpp"
#include "app/viz/plot.hpp"
#include "app/viz/plot_raster.hpp"

namespace app {

namespace {

std::string number(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream out;
  out << std::setprecision(10) << v;
  return out.str();
}

const char* const csv_header =
    "scene,topology,nodes,cache_pages,predicted_seconds,predicted_hms,speedup,efficiency,miss_ratio,"
    "page_requests,page_accesses,pages_per_pixel,mean_hops,messages,rays,wall_seconds,paper_seconds,deviation";

std::string kind_name(SweepOptions::Kind kind) { return kind == SweepOptions::Kind::nodes ? "nodes" : "cache"; }

// The paper's Table 2 time for a point of a nodes sweep, where it printed one.
// A cache sweep has none: Table 2 was measured with the whole memory as cache.
std::optional<double> paper_seconds(const SweepTable& t, const ExperimentPoint& p) {
  if (t.kind != SweepOptions::Kind::nodes) return std::nullopt;
  return paper_synthesis_seconds(t.scene, t.width, t.height, p.nodes);
}

bool has_paper_figures(const SweepTable& t) {
  for (const ExperimentPoint& p : t.points)
    if (paper_seconds(t, p)) return true;
  return false;
}

// "+4.4%"
std::string signed_percent(double fraction) {
  std::ostringstream out;
  out << std::showpos << std::fixed << std::setprecision(1) << 100 * fraction << "%";
  return out.str();
}

// One series per kind of topology ("hypercube:3" and "hypercube:4" are one
// line): y(point) against the sweep's axis.
std::vector<viz::Series> series_of(const SweepTable& t, double (*y)(const ExperimentPoint&)) {
  std::map<std::string, std::size_t> index;
  std::vector<viz::Series> series;
  for (const ExperimentPoint& p : t.points) {
    const std::string kind = p.topology.substr(0, p.topology.find(':'));
    auto [it, fresh] = index.try_emplace(kind, series.size());
    if (fresh) series.push_back(viz::Series{.name = kind});
    const double x = t.kind == SweepOptions::Kind::nodes ? p.nodes : p.cache_pages;
    series[it->second].points.push_back({x, y(p)});
  }
  return series;
}

// "<scene> <W>x<H>[ on <topology>], <what stays fixed>: <what>": the
// topology when the plot has only one (then no legend names it), and the
// cache of a nodes sweep or the nodes of a cache sweep when every point
// shares it. The axes say what the plot is against.
std::string title_of(const SweepTable& t, const std::vector<viz::Series>& series, const std::string& what) {
  std::string title = t.scene + " " + std::to_string(t.width) + "x" + std::to_string(t.height);
  if (series.size() == 1) title += " on " + series.front().name;
  const bool nodes = t.kind == SweepOptions::Kind::nodes;
  const auto fixed = [&](const ExperimentPoint& p) {
    return nodes ? std::uint64_t(p.cache_pages) : std::uint64_t(p.nodes);
  };
  const bool shared = !t.points.empty() && std::all_of(t.points.begin(), t.points.end(), [&](const ExperimentPoint& p) {
    return fixed(p) == fixed(t.points.front());
  });
  if (shared) title += ", " + std::to_string(fixed(t.points.front())) + (nodes ? " pages of cache" : " nodes");
  return title + ": " + what;
}

std::vector<viz::LinePlot> nodes_plots(const SweepTable& t) {
  viz::LinePlot time{
      .x_label = "processors", .y_label = "seconds", .x_scale = viz::AxisScale::log2, .y_scale = viz::AxisScale::log10};
  time.series = series_of(t, [](const ExperimentPoint& p) { return p.predicted_seconds; });
  time.title = title_of(t, time.series, "predicted synthesis time");
  viz::Series paper{.name = "paper (iPSC/2)", .style = viz::LineStyle::dashed};
  for (const ExperimentPoint& p : t.points)
    if (const auto s = paper_seconds(t, p); s && (paper.points.empty() || paper.points.back().x < p.nodes))
      paper.points.push_back({double(p.nodes), *s});
  if (!paper.points.empty()) time.series.push_back(paper);
  viz::LinePlot eff{.x_label = "processors",
                    .y_label = "efficiency (%)",
                    .x_scale = viz::AxisScale::log2,
                    .y_min = 0.0,
                    .y_max = 105.0};
  eff.series = series_of(t, [](const ExperimentPoint& p) { return 100 * p.efficiency(); });
  eff.title = title_of(t, eff.series, "efficiency");
  eff.thresholds.push_back({78, "paper: 78% at 64"});
  viz::LinePlot speed{
      .x_label = "processors", .y_label = "speedup", .x_scale = viz::AxisScale::log2, .y_scale = viz::AxisScale::log2};
  speed.series = series_of(t, [](const ExperimentPoint& p) { return p.speedup(); });
  speed.title = title_of(t, speed.series, "speedup");
  viz::Series ideal{.name = "ideal", .style = viz::LineStyle::dashed, .markers = false};
  for (const auto& p : speed.series.front().points) ideal.points.push_back({p.x, p.x});
  speed.series.push_back(ideal);
  return {time, speed, eff};
}

std::vector<viz::LinePlot> cache_plots(const SweepTable& t) {
  viz::LinePlot eff{.x_label = "cache (pages)",
                    .y_label = "efficiency (%)",
                    .x_scale = viz::AxisScale::log2,
                    .y_min = 0.0,
                    .y_max = 105.0};
  eff.series = series_of(t, [](const ExperimentPoint& p) { return 100 * p.efficiency(); });
  eff.title = title_of(t, eff.series, "efficiency");
  eff.thresholds.push_back({50, "50% threshold"});
  viz::LinePlot miss{.x_label = "cache (pages)", .y_label = "miss ratio (%)", .x_scale = viz::AxisScale::log2};
  miss.series = series_of(t, [](const ExperimentPoint& p) { return 100 * p.miss_ratio; });
  miss.title = title_of(t, miss.series, "miss ratio");
  viz::LinePlot comm{.x_label = "cache (pages)", .y_label = "pages sent", .x_scale = viz::AxisScale::log2};
  comm.series = series_of(t, [](const ExperimentPoint& p) { return double(p.misses); });
  comm.title = title_of(t, comm.series, "page communications (pages sent)");
  return {eff, miss, comm};
}

viz::Table html_table(const SweepTable& t) {
  viz::Table table{.caption = "Virtual-time runs (" + t.model.describe() + ")",
                   .header = {"topology", "N", "cache", "predicted", "speedup", "efficiency", "miss ratio",
                              "page requests", "mean hops", "wall s"}};
  const bool paper = has_paper_figures(t);
  if (paper) table.header.insert(table.header.begin() + 4, {"paper", "vs paper"});
  for (const ExperimentPoint& p : t.points) {
    std::ostringstream eff, miss, hops, speed, wall;
    eff << std::fixed << std::setprecision(1) << 100 * p.efficiency() << "%";
    miss << std::fixed << std::setprecision(2) << 100 * p.miss_ratio << "%";
    hops << std::fixed << std::setprecision(2) << p.mean_hops;
    speed << std::fixed << std::setprecision(2) << p.speedup();
    wall << std::fixed << std::setprecision(1) << p.wall_seconds;
    std::vector<std::string> row{p.topology,
                                 std::to_string(p.nodes),
                                 std::to_string(p.cache_pages),
                                 paper_duration(p.predicted_seconds),
                                 speed.str(),
                                 eff.str(),
                                 miss.str(),
                                 std::to_string(p.misses),
                                 hops.str(),
                                 wall.str()};
    if (paper) {
      const auto s = paper_seconds(t, p);
      row.insert(row.begin() + 4,
                 {s ? paper_duration(*s) : "", s ? signed_percent(deviation_from(p.predicted_seconds, *s)) : ""});
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace

std::vector<viz::LinePlot> sweep_plots(const SweepTable& t) {
  return t.kind == SweepOptions::Kind::nodes ? nodes_plots(t) : cache_plots(t);
}

std::string sweep_csv(const SweepTable& t) {
  std::ostringstream out;
  out << csv_header << "\n";
  for (const ExperimentPoint& p : t.points) {
    out << t.scene << "," << p.topology << "," << p.nodes << "," << p.cache_pages << "," << number(p.predicted_seconds)
        << "," << paper_duration(p.predicted_seconds) << "," << number(p.speedup()) << "," << number(p.efficiency())
        << "," << number(p.miss_ratio) << "," << p.misses << "," << p.page_accesses << "," << number(p.pages_per_pixel)
        << "," << number(p.mean_hops) << "," << p.messages << "," << p.rays << "," << number(p.wall_seconds) << ",";
    if (const auto paper = paper_seconds(t, p))
      out << number(*paper) << "," << number(deviation_from(p.predicted_seconds, *paper));
    else
      out << ",";
    out << "\n";
  }
  return out.str();
}

std::string sweep_json(const SweepTable& t) {
  Json points = Json::array();
  for (const ExperimentPoint& p : t.points) {
    const auto paper = paper_seconds(t, p);
    points.push_back({{"topology", p.topology},
                      {"nodes", p.nodes},
                      {"cache_pages", p.cache_pages},
                      {"predicted_seconds", p.predicted_seconds},
                      {"speedup", p.speedup()},
                      {"efficiency", p.efficiency()},
                      {"miss_ratio", p.miss_ratio},
                      {"page_requests", p.misses},
                      {"page_accesses", p.page_accesses},
                      {"pages_per_pixel", p.pages_per_pixel},
                      {"mean_hops", p.mean_hops},
                      {"messages", p.messages},
                      {"rays", p.rays},
                      {"wall_seconds", p.wall_seconds},
                      {"paper_seconds", paper ? Json(*paper) : Json()},
                      {"deviation", paper ? Json(deviation_from(p.predicted_seconds, *paper)) : Json()}});
  }
  // A number that is not finite is written as null.
  const Json j = {{"schema_version", sweep_schema_version},
                  {"vmpray_version", VMPRAY_VERSION},
                  {"command_line", t.command_line},
                  {"sweep", kind_name(t.kind)},
                  {"scene", t.scene},
                  {"width", t.width},
                  {"height", t.height},
                  {"pages", t.page_count},
                  {"tracing", t.tracing},
                  {"farming", t.farming},
                  {"cost_model", cost_model_json(t.model)},
                  {"serial_seconds", t.serial_seconds},
                  {"points", std::move(points)}};
  return dump_json(j, 2) + "\n";
}

std::vector<std::filesystem::path> write_sweep(const SweepTable& t, const std::filesystem::path& dir,
                                               OutputFiles& outputs) {
  if (!std::filesystem::exists(dir)) outputs.add(dir);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error(dir.string() + ": cannot create the directory: " + error.message());
  const std::string stem = kind_name(t.kind);
  const auto plots = sweep_plots(t);
  std::vector<std::filesystem::path> files;
  files.push_back(outputs.write_text(dir / (stem + ".csv"), sweep_csv(t)));
  files.push_back(outputs.write_text(dir / (stem + ".json"), sweep_json(t)));
  files.push_back(outputs.write_text(dir / (stem + ".svg"), viz::plots_svg(plots, static_cast<int>(plots.size()))));
  for (std::size_t i = 0; i < plots.size(); ++i)
    files.push_back(outputs.write(dir / (stem + "-" + std::to_string(i + 1) + "-plot.png"),
                                  [&](const auto& path) { viz::plot_image(plots[i]).write_image(path.string()); }));
  viz::Report report{.title = "vmpray sweep " + stem + ": " + t.scene,
                     .version = "vmpray " VMPRAY_VERSION,
                     .command_line = t.command_line};
  viz::Section section{.heading = t.scene + " at " + std::to_string(t.width) + "x" + std::to_string(t.height) +
                                  ", " + std::to_string(t.page_count) + " pages, " + t.tracing + "; " + t.farming};
  section.blocks.push_back(viz::Paragraph{"T1 (one node, same model) = " + paper_duration(t.serial_seconds) +
                                          "; efficiency = T1 / (N * TN)."});
  if (has_paper_figures(t))
    section.blocks.push_back(viz::Paragraph{
        "The paper's Table 2 (a 64-node iPSC/2 hypercube, the whole memory as cache) beside each point it has a "
        "time for; \"vs paper\" is predicted / paper - 1."});
  else if (t.kind == SweepOptions::Kind::cache)
    section.blocks.push_back(viz::Paragraph{
        "The paper gives Figure 8 as curves, with no figures to set beside these; it draws the 50% efficiency "
        "threshold shown here, and reports its network saturated on Rings4 below 204 pages of cache."});
  section.blocks.push_back(html_table(t));
  section.blocks.push_back(viz::SvgFigure{.caption = stem + " sweep", .svg = viz::plots_svg(plots, 1)});
  report.sections.push_back(section);
  files.push_back(outputs.write_text(dir / (stem + ".html"), viz::html_report(report)));
  return files;
}

int sweep_main(int argc, const char* const argv[]) {
  SweepOptions options;
  try {
    options = parse_sweep_options(argc, argv);
  } catch (const UsageError& e) {
    if (std::string(e.what()) == "help") {
      std::cout << sweep_usage();
      return 0;
    }
    std::cerr << "vmpray sweep: " << e.what() << " (see vmpray sweep --help)\n";
    return 2;
  }
  try {
    SweepTable table = run_sweep(options, options.quiet ? nullptr : &std::cerr);
    table.command_line.assign(argv, argv + argc);
    table.command_line.insert(table.command_line.begin(), "vmpray");
    OutputPhase phase;
    const auto files = write_sweep(table, options.out_dir, phase.files());
    if (!options.quiet) {
      std::cout << sweep_csv(table);
      std::cout << "machine model " << table.model.describe() << "\n";  // with a fitted unit, the fit
      std::cout << "wrote " << files.size() << " files in " << options.out_dir.string() << "\n";
    }
    return phase.finish(std::cout, "table");
  } catch (const UsageError& e) {  // found in the run: a machine too large for the memory
    std::cerr << "vmpray sweep: " << e.what() << "\n";
    return 2;
  } catch (const nodes::ResourceError& e) {  // each point runs on a thread of its own
    std::cerr << "vmpray sweep: " << with_hint(e, "--jobs, " + std::to_string(options.jobs) + " here") << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "vmpray sweep: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace app
