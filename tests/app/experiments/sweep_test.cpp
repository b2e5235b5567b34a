// vmpray sweep: option errors, the CSV/JSON tables and SVG plots it writes
// (parsed here), the HTML page linking only files it wrote, the same sweep
// giving the same predictions twice and on any number of jobs, which
// failure a sweep of points run side by side reports, and a machine too
// large for the memory refused before any run.
#include "app/experiments/sweep.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "app/experiments/paper_figures.hpp"
#include "app/experiments/points.hpp"
#include "app/render/options.hpp"
#include "tests/app/viz/xml_check.hpp"
#include "tests/support/scratch.hpp"
#include "tracer/generators.hpp"

namespace {

namespace fs = std::filesystem;

app::SweepOptions parse(std::vector<const char*> args) {
  args.insert(args.begin(), "sweep");
  return app::parse_sweep_options(static_cast<int>(args.size()), args.data());
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> cells{""};  // every comma starts a cell, empty ones at the end too
    for (char c : line) {
      if (c == ',')
        cells.emplace_back();
      else
        cells.back() += c;
    }
    rows.push_back(cells);
  }
  return rows;
}

// The same sweep run without and with `extra` options.
std::pair<app::SweepTable, app::SweepTable> without_and_with(const std::vector<const char*>& args,
                                                              std::initializer_list<const char*> extra) {
  std::vector<const char*> more = args;
  more.insert(more.end(), extra);
  return {app::run_sweep(parse(args), nullptr), app::run_sweep(parse(more), nullptr)};
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  return dir;
}

TEST(SweepOptions, BadValuesNameTheOption) {
  const std::vector<std::pair<std::vector<const char*>, std::string>> cases{
      {{"sideways"}, "expected 'nodes' or 'cache' after 'sweep', got 'sideways'"},
      {{"nodes", "--nodes", "1,x"}, "--nodes"},
      {{"cache", "--cache-pages", "0"}, "--cache-pages"},
      {{"nodes", "--cost", "box=slow"}, "--cost"},
      {{"nodes", "--size", "0"}, "--size"},
      {{"nodes", "--shadow-rays", "some"}, "--shadow-rays"},
      {{"nodes", "--accel", "kd"}, "--accel"},
      {{"nodes", "--bvh-layout", "veb"}, "--bvh-layout"},
      {{"nodes", "--prefetch", "4"}, "--prefetch"},
      {{"nodes", "--schedule", "guided"}, "--schedule"},
      {{"nodes", "--pixel-order", "zorder"}, "--pixel-order"},
      // Negative numbers must not wrap around into huge unsigned values.
      {{"nodes", "--grain", "-1"}, "--grain: must not be negative, got -1"},
      {{"nodes", "--prefetch", "-1"}, "--prefetch: must not be negative, got -1"},
      // The machine's bounds, checked by the machine's own rules.
      {{"nodes", "--grain", "0"}, "--grain: must be at least 1, got 0"},
      {{"nodes", "--grain", "1048577"}, "--grain: must be at most 1048576, got 1048577"},
      {{"nodes", "--prefetch", "70000"}, "--prefetch: is too large, got 70000"},
      {{"nodes", "--page-size", "-1"}, "--page-size: page size -1"},
      {{"nodes", "--jobs", "-1"}, "--jobs: expected 0..1024, got -1"},
      {{"nodes", "--page-size", "1000"}, "--page-size: page size 1000"},
      // Every machine is checked before the first one runs.
      {{"nodes", "--nodes", "1,3"}, "--topology: topology 'hypercube': a hypercube needs a power of two nodes, not 3"},
      {{"nodes", "--topology", "ring,bogus"}, "--topology: topology 'bogus'"},
      {{"nodes", "--topology", "hypercube:2", "--nodes", "4,8"}, "--topology: topology 'hypercube:2'"},
      // The axis not swept takes one value.
      {{"cache", "--nodes", "4,8"}, "--nodes: a cache sweep runs one machine size, got 4,8"},
      {{"nodes", "--cache-pages", "4,8"}, "--cache-pages: a nodes sweep runs one cache size, got 4,8"},
      // Zero would otherwise mean "no fit" in silence.
      {{"nodes", "--fit-seconds", "0"}, "--fit-seconds"},
      {{"nodes", "--fit-seconds", "inf"}, "--fit-seconds"},
      {{"nodes", "--schedule", "static", "--grain", "8"}, "--grain: the static schedule hands out fixed shares"},
      // A value twice would be a second run and a line doubling back.
      {{"nodes", "--nodes", "2,4,2"}, "--nodes: 2 is listed twice"},
      {{"cache", "--cache-pages", "8,8"}, "--cache-pages: 8 is listed twice"},
      {{"cache", "--cache-pages", "4294967297"}, "--cache-pages: expected positive integers, got '4294967297'"},
      {{"nodes", "--topology", "ring,ring"}, "--topology: ring is listed twice"},
      // Given empty, a list is a mistake, not the default list.
      {{"nodes", "--nodes", ""}, "--nodes: empty list"},
      {{"cache", "--cache-pages", ""}, "--cache-pages: empty list"},
      // A sized spec does not fit the default node counts: say so, not "asked for 1".
      {{"nodes", "--topology", "mesh:4x4"},
       "--topology: mesh:4x4 has a size of its own, which the default --nodes list does not fit"},
  };
  for (const auto& [args, option] : cases) {
    try {
      parse(args);
      ADD_FAILURE() << option << " accepted";
    } catch (const app::UsageError& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
    }
  }
}

// A plot's line runs along the axis in increasing order, whatever the order given.
TEST(SweepOptions, TheSweptAxisRunsInIncreasingOrder) {
  EXPECT_EQ(parse({"nodes", "--nodes", "4,1,16,2"}).nodes, (std::vector<std::size_t>{1, 2, 4, 16}));
  EXPECT_EQ(parse({"cache", "--cache-pages", "64,8,32"}).cache_pages, (std::vector<std::uint32_t>{8, 32, 64}));
}

// Known before the runs, which may take minutes, rather than after them.
TEST(SweepOptions, AnOutputPathThatIsAFileIsAnError) {
  const fs::path file = fresh_dir("vmpray_sweep_out_file");
  std::ofstream(file) << "not a directory\n";
  try {
    parse({"nodes", "--out", file.c_str()});
    ADD_FAILURE() << "accepted";
  } catch (const app::UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "--out: cannot write in '" + file.string() + "': " + file.string() +
                                         ": Not a directory");
  }
  fs::remove(file);
}

// A directory to be made under a file, or in a directory that is not
// there, is refused as soon: the nearest existing parent must take it.
TEST(SweepOptions, AnOutputDirectoryThatCannotBeMadeIsAnError) {
  const fs::path file = fresh_dir("vmpray_sweep_out_parent");
  std::ofstream(file) << "not a directory\n";
  const std::pair<fs::path, std::string> refused[] = {
      {file / "sub", file.string() + ": Not a directory"},
      {file / "a" / "b", file.string() + ": Not a directory"},
  };
  for (const auto& [out, reason] : refused) {
    try {
      parse({"nodes", "--out", out.c_str()});
      ADD_FAILURE() << "accepted " << out;
    } catch (const app::UsageError& e) {
      EXPECT_EQ(std::string(e.what()), "--out: cannot write in '" + out.string() + "': " + reason);
    }
  }
  fs::remove(file);
  EXPECT_EQ(parse({"nodes", "--out", (fs::temp_directory_path() / "vmpray_no_such_dir" / "out").c_str()}).out_dir,
            fs::temp_directory_path() / "vmpray_no_such_dir" / "out");
}

TEST(SweepOptions, ShadowRaysAndAccelReachTheRuns) {
  EXPECT_FALSE(parse({"nodes"}).trace.shadow_rays_to_all_lights);
  const auto o = parse({"nodes", "--shadow-rays", "all", "--accel", "grid"});
  EXPECT_TRUE(o.trace.shadow_rays_to_all_lights);
  EXPECT_EQ(o.accel, tracer::Accel::grid);
}

TEST(SweepOptions, CacheSweepDefaultsToSixteenNodes) {
  const auto o = parse({"cache", "rings4", "--cache-pages", "4,8"});
  EXPECT_EQ(o.kind, app::SweepOptions::Kind::cache);
  EXPECT_EQ(o.scene, "rings4");
  EXPECT_EQ(o.nodes, std::vector<std::size_t>{16});
  EXPECT_EQ(o.cache_pages, (std::vector<std::uint32_t>{4, 8}));
}

TEST(Sweep, NodesSweepWritesWellFormedTablesAndPlots) {
  const fs::path dir = fresh_dir("vmpray_sweep_nodes");
  auto o = parse({"nodes", "teapot:2", "--size", "12", "--nodes", "1,2,4", "--topology", "hypercube,ring"});
  app::SweepTable table = app::run_sweep(o, nullptr);
  table.command_line = {"vmpray", "sweep", "nodes", "teapot:2"};
  app::OutputFiles outputs;
  const auto files = app::write_sweep(table, dir, outputs);
  outputs.keep();

  const auto rows = csv_rows(read(dir / "nodes.csv"));
  ASSERT_EQ(rows.size(), 7u);  // header + 2 topologies x 3 sizes
  for (const auto& row : rows) EXPECT_EQ(row.size(), rows.front().size());
  EXPECT_EQ(rows[0][5], "predicted_hms");  // the predicted time written as the paper writes times
  EXPECT_EQ(rows[1][2], "1");
  EXPECT_DOUBLE_EQ(std::stod(rows[1][7]), 1.0);  // efficiency of N = 1
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_GT(std::stod(rows[i][4]), 0.0);

  const std::string json = read(dir / "nodes.json");
  EXPECT_EQ(std::count(json.begin(), json.end(), '{'), std::count(json.begin(), json.end(), '}'));
  EXPECT_EQ(std::count(json.begin(), json.end(), '['), std::count(json.begin(), json.end(), ']'));
  EXPECT_NE(json.find("\"efficiency\": 1.0,"), std::string::npos);
  EXPECT_NE(json.find("\"tracing\": \"bvh, treelet layout, shadow rays facing\""), std::string::npos);
  EXPECT_NE(json.find("\"farming\": \"dynamic schedule, grain 4, prefetch 0, scanline order\""), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
  const nlohmann::json doc = nlohmann::json::parse(json);
  EXPECT_EQ(doc.at("schema_version"), app::sweep_schema_version);
  EXPECT_EQ(doc.at("vmpray_version"), VMPRAY_VERSION);
  EXPECT_EQ(doc.at("command_line"), nlohmann::json(table.command_line));
  EXPECT_EQ(doc.at("points").size(), 6u);
  // The page stands alone and says what made it.
  const std::string html = read(dir / "nodes.html");
  EXPECT_NE(html.find("Made by vmpray " VMPRAY_VERSION " with <code>vmpray sweep nodes teapot:2</code>"),
            std::string::npos);
  EXPECT_EQ(html.find("src=\"nodes-"), std::string::npos);

  // One series per kind of topology, whatever the node count; the titles say
  // the scene, the image and the cache every point shares.
  const auto plots = app::sweep_plots(table);
  ASSERT_EQ(plots.size(), 3u);
  for (const viz::LinePlot& plot : plots) {
    EXPECT_EQ(plot.series.at(0).name, "hypercube") << plot.title;
    EXPECT_EQ(plot.series.at(1).name, "ring") << plot.title;
    EXPECT_EQ(plot.series.at(0).points.size(), 3u) << plot.title;
    EXPECT_EQ(
        plot.title.rfind("teapot:2 12x12, " + std::to_string(table.points[0].cache_pages) + " pages of cache: ", 0), 0u)
        << plot.title;
  }
  const std::string svg_text = read(dir / "nodes.svg");
  const auto svg = viz::test::check_xml(svg_text);
  EXPECT_TRUE(svg.ok) << svg.error;
  EXPECT_TRUE(svg_text.starts_with("<svg")) << svg_text.substr(0, 40);
  for (const auto& f : files) EXPECT_TRUE(fs::exists(f)) << f;
}

TEST(Sweep, ShadowRaysToAllLightsCountMoreRaysAndTakeLonger) {
  auto o = parse({"nodes", "teapot:2", "--size", "12", "--nodes", "2"});
  const app::SweepTable facing = app::run_sweep(o, nullptr);
  o.trace.shadow_rays_to_all_lights = true;
  const app::SweepTable all = app::run_sweep(o, nullptr);
  ASSERT_EQ(all.points.size(), 1u);
  EXPECT_GT(all.points[0].rays, facing.points[0].rays);
  EXPECT_GT(all.serial_seconds, facing.serial_seconds);
  EXPECT_EQ(all.tracing, "bvh, treelet layout, shadow rays all");
}

// The affinity schedule reaches the runs: the same rays, fewer farming
// messages (its early tiles are larger than the grain).
TEST(Sweep, AffinityScheduleReachesTheRuns) {
  const auto [dynamic, affinity] = without_and_with(
      {"nodes", "teapot:2", "--size", "24", "--nodes", "4", "--grain", "1"}, {"--schedule", "affinity"});
  ASSERT_EQ(affinity.points.size(), 1u);
  EXPECT_EQ(affinity.points[0].rays, dynamic.points[0].rays);
  EXPECT_LT(affinity.points[0].messages, dynamic.points[0].messages);
  EXPECT_EQ(affinity.farming, "affinity schedule, grain 1, prefetch 0, scanline order");
}

// The Hilbert order reaches the runs: the same rays, and static shares that
// are compact patches miss less than bands of rows.
TEST(Sweep, HilbertOrderReachesTheRuns) {
  const auto [scanline, hilbert] = without_and_with(
      {"nodes", "teapot:3", "--size", "32", "--nodes", "16", "--cache-pages", "12", "--schedule", "static"},
      {"--pixel-order", "hilbert"});
  ASSERT_EQ(hilbert.points.size(), 1u);
  EXPECT_EQ(hilbert.points[0].rays, scanline.points[0].rays);
  EXPECT_LT(hilbert.points[0].misses, scanline.points[0].misses);
  EXPECT_EQ(hilbert.farming, "static schedule, prefetch 0, hilbert order");  // fixed shares: no grain
}

// The BVH layout reaches the runs: the same rays, and more page accesses
// when siblings rather than treelets share pages.
TEST(Sweep, BvhLayoutReachesTheRuns) {
  const auto [treelet, depth_first] = without_and_with(
      {"cache", "teapot:3", "--size", "32", "--nodes", "4", "--cache-pages", "8"}, {"--bvh-layout", "depth-first"});
  ASSERT_EQ(depth_first.points.size(), 1u);
  EXPECT_EQ(depth_first.points[0].rays, treelet.points[0].rays);
  EXPECT_GT(depth_first.points[0].page_accesses, treelet.points[0].page_accesses);
  EXPECT_EQ(depth_first.tracing, "bvh, depth-first layout, shadow rays facing");
}

TEST(Sweep, CacheSweepCountsFewerMissesWithMoreCache) {
  auto o = parse({"cache", "teapot:2", "--size", "12", "--nodes", "4", "--cache-pages", "2,64"});
  const app::SweepTable table = app::run_sweep(o, nullptr);
  ASSERT_EQ(table.points.size(), 2u);
  EXPECT_GT(table.points[0].misses, table.points[1].misses);
  EXPECT_GT(table.points[0].miss_ratio, table.points[1].miss_ratio);
}

// The HTML page goes last; when it cannot be written (a directory stands at
// its path) the tables and plots written before it are removed again.
TEST(Sweep, AFileThatCannotBeWrittenTakesTheOthersWithIt) {
  const fs::path dir = fresh_dir("vmpray_sweep_failed");
  fs::create_directories(dir / "cache.html");
  auto o = parse({"cache", "teapot:2", "--size", "8", "--nodes", "2", "--cache-pages", "4,8"});
  {
    app::OutputFiles outputs;  // removes, as it ends, what was written
    EXPECT_THROW(app::write_sweep(app::run_sweep(o, nullptr), dir, outputs), std::runtime_error);
  }
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"cache.html"});
}

// The page holds its figures; it names no other file.
TEST(Sweep, HtmlPageStandsAlone) {
  const fs::path dir = fresh_dir("vmpray_sweep_html");
  auto o = parse({"cache", "teapot:2", "--size", "8", "--nodes", "2", "--cache-pages", "4,8"});
  app::OutputFiles outputs;
  const auto files = app::write_sweep(app::run_sweep(o, nullptr), dir, outputs);
  outputs.keep();
  const std::string html = read(dir / "cache.html");
  const std::regex link(R"((?:src|href)=\"([^\"]*)\")");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), link); it != std::sregex_iterator(); ++it)
    EXPECT_TRUE((*it)[1].str().starts_with("#")) << (*it)[1].str();
  EXPECT_NE(html.find("<svg"), std::string::npos);
  // The paper prints Figure 8 as curves: the page says so rather than showing numbers it does not have.
  EXPECT_NE(html.find("Figure 8 as curves"), std::string::npos);
  EXPECT_EQ(html.find("vs paper"), std::string::npos);
}

TEST(PaperFigures, Table2AsPrintedAndNothingElse) {
  EXPECT_EQ(app::paper_synthesis_seconds("teapot", 512, 512, 1), 3 * 3600 + 12 * 60 + 2);
  EXPECT_EQ(app::paper_synthesis_seconds("mountain", 512, 512, 64), 5 * 60 + 7);
  EXPECT_EQ(app::paper_synthesis_seconds("rings4", 512, 512, 2), 4 * 3600 + 58 * 60 + 46);
  EXPECT_EQ(app::paper_synthesis_seconds("tetra9", 512, 512, 16), 4 * 60 + 55);
  EXPECT_EQ(app::paper_synthesis_seconds("tetra10", 512, 512, 64), 3 * 60 + 46);
  EXPECT_FALSE(app::paper_synthesis_seconds("rings4", 512, 512, 1));    // not printed
  EXPECT_FALSE(app::paper_synthesis_seconds("tetra10", 512, 512, 32));  // not printed
  EXPECT_FALSE(app::paper_synthesis_seconds("teapot", 512, 512, 3));    // not a column
  EXPECT_FALSE(app::paper_synthesis_seconds("teapot", 512, 512, 128));
  EXPECT_FALSE(app::paper_synthesis_seconds("teapot", 256, 256, 1));    // another image
  EXPECT_FALSE(app::paper_synthesis_seconds("teapot:2", 512, 512, 1));  // another scene
}

// A nodes sweep of a paper scene at 512x512 puts Table 2 beside each point
// the paper has, in the CSV, the JSON, the page's table and the time plot.
TEST(Sweep, APaperSceneGetsTable2BesideItsPoints) {
  app::SweepTable t;
  t.kind = app::SweepOptions::Kind::nodes;
  t.scene = "teapot";
  t.width = t.height = 512;
  t.serial_seconds = 12674.2;
  for (int n : {1, 3}) {
    app::ExperimentPoint p;
    p.topology = "ring:" + std::to_string(n);
    p.nodes = n;
    p.cache_pages = 3072;
    p.predicted_seconds = t.serial_seconds / n;
    p.serial_seconds = t.serial_seconds;
    t.points.push_back(p);
  }
  const auto rows = csv_rows(app::sweep_csv(t));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0][16], "paper_seconds");
  EXPECT_EQ(rows[0][17], "deviation");
  EXPECT_EQ(rows[1][16], "11522");
  EXPECT_NEAR(std::stod(rows[1][17]), 0.1, 1e-6);
  ASSERT_EQ(rows[2].size(), rows[0].size());  // N = 3: no figure, empty cells
  EXPECT_EQ(rows[2][16], "");
  const nlohmann::json j = nlohmann::json::parse(app::sweep_json(t));
  EXPECT_EQ(j.at("points")[0].at("paper_seconds"), 11522);
  EXPECT_NEAR(j.at("points")[0].at("deviation").get<double>(), 0.1, 1e-6);
  EXPECT_TRUE(j.at("points")[1].at("paper_seconds").is_null());
  EXPECT_TRUE(j.at("points")[1].at("deviation").is_null());

  const fs::path dir = fresh_dir("vmpray_sweep_paper");
  app::OutputFiles outputs;
  app::write_sweep(t, dir, outputs);
  outputs.keep();
  const std::string html = read(dir / "nodes.html");
  EXPECT_NE(html.find("<th>vs paper</th>"), std::string::npos);
  EXPECT_NE(html.find(">3h12mn02s</td>"), std::string::npos);
  EXPECT_NE(html.find(">+10.0%</td>"), std::string::npos);
  EXPECT_NE(html.find("Table 2"), std::string::npos);

  // The time plot has the paper's line; the title names the one topology.
  const auto plots = app::sweep_plots(t);
  ASSERT_EQ(plots[0].series.size(), 2u);
  EXPECT_EQ(plots[0].series[1].name, "paper (iPSC/2)");
  ASSERT_EQ(plots[0].series[1].points.size(), 1u);  // N = 1 only: the paper has no N = 3
  EXPECT_EQ(plots[0].series[1].points[0].y, 11522);
  EXPECT_EQ(plots[0].title.rfind("teapot 512x512 on ring, 3072 pages of cache: predicted synthesis time", 0), 0u)
      << plots[0].title;

  t.scene = "teapot:2";  // not the paper's scene: nothing beside it
  EXPECT_EQ(csv_rows(app::sweep_csv(t))[1][16], "");
  EXPECT_TRUE(nlohmann::json::parse(app::sweep_json(t)).at("points")[0].at("paper_seconds").is_null());
}

TEST(Sweep, SameSweepGivesSamePredictions) {
  auto o = parse({"nodes", "teapot:2", "--size", "10", "--nodes", "4"});
  const auto a = app::run_sweep(o, nullptr);
  const auto b = app::run_sweep(o, nullptr);
  EXPECT_EQ(a.serial_seconds, b.serial_seconds);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].predicted_seconds, b.points[i].predicted_seconds);
    EXPECT_EQ(a.points[i].misses, b.points[i].misses);
    EXPECT_EQ(a.points[i].rays, b.points[i].rays);
    EXPECT_EQ(a.points[i].mean_hops, b.points[i].mean_hops);
  }
}

// Points run side by side: the same figures as one by one, and the progress
// lines in the table's order however the runs finish.
TEST(Sweep, PointsRunSideBySideGiveTheTableOfOneByOne) {
  auto o = parse({"nodes", "teapot:2", "--size", "12", "--nodes", "1,2,4,8", "--topology", "hypercube,ring",
                  "--fit-seconds", "100"});
  o.jobs = 1;
  std::ostringstream one_progress;
  const app::SweepTable one = app::run_sweep(o, &one_progress);
  o.jobs = 3;
  std::ostringstream three_progress;
  const app::SweepTable three = app::run_sweep(o, &three_progress);
  EXPECT_EQ(one.model.unit, three.model.unit);
  EXPECT_EQ(one.serial_seconds, three.serial_seconds);
  ASSERT_EQ(one.points.size(), 8u);
  ASSERT_EQ(three.points.size(), one.points.size());
  for (std::size_t i = 0; i < one.points.size(); ++i) {
    const app::ExperimentPoint &a = one.points[i], &b = three.points[i];
    EXPECT_EQ(a.topology, b.topology) << i;
    EXPECT_EQ(a.nodes, b.nodes) << i;
    EXPECT_EQ(a.predicted_seconds, b.predicted_seconds) << i;
    EXPECT_EQ(a.serial_seconds, b.serial_seconds) << i;
    EXPECT_EQ(a.misses, b.misses) << i;
    EXPECT_EQ(a.messages, b.messages) << i;
    EXPECT_EQ(a.rays, b.rays) << i;
  }
  const auto lines_of = [](const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line.substr(0, line.find(" (wall")));
    return lines;
  };
  const auto one_lines = lines_of(one_progress.str());
  ASSERT_EQ(one_lines.size(), one.points.size());
  EXPECT_EQ(lines_of(three_progress.str()), one_lines);
  EXPECT_EQ(one_lines.front().rfind("hypercube:0 N=1 cache=", 0), 0u) << one_lines.front();
  EXPECT_EQ(one_lines.back().rfind("ring:8 N=8 cache=", 0), 0u) << one_lines.back();
}

// Of several failing points the first in order is reported, as one by one,
// and no point after a failure is reported done.
TEST(Sweep, SideBySideRunsReportTheFirstFailureInOrder) {
  tracer::Scene scene = tracer::generate_scene("teapot:2");
  scene.camera.width = scene.camera.height = 8;
  const tracer::Database db = tracer::build_database(scene, {});
  std::vector<app::ExperimentSetup> setups(6);
  setups[2].cache_pages = 0;  // refused: a cache holds a page at least
  setups[4].farming.prefetch = 1000;  // refused: more than a node can hold
  for (const unsigned jobs : {1u, 2u, 6u}) {
    std::vector<std::size_t> done;
    try {
      app::run_points(db, setups, jobs, [&](std::size_t i, const app::ExperimentPoint&) { done.push_back(i); });
      ADD_FAILURE() << "no failure with " << jobs << " jobs";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("cache_pages"), std::string::npos) << jobs << " jobs: " << e.what();
    }
    EXPECT_EQ(done, (std::vector<std::size_t>{0, 1})) << jobs << " jobs";
  }
}

class SweepCli : public test::ScratchTest {
 protected:
  SweepCli() : ScratchTest("vmpray_sweep_cli_") {}
};

// A complete graph of 2048 nodes has 4 million link queues, each carried by
// a process in virtual time: refused in one line, with nothing written.
TEST_F(SweepCli, AMachineTooLargeForTheMemoryIsRefusedBeforeAnyRun) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 2 GB of address space";
#endif
  const test::Outcome r = run_vmpray("sweep nodes --scene teapot:2 --size 8 --topology complete --nodes 1,2048 --out out",
                                     "stdout.txt", "ulimit -v 2000000");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "vmpray sweep: --nodes/--topology: complete:2048 (2048 nodes, 4192256 link queues) needs about 1332.5 GB "
            "of address space with its image, more than the 2.0 GB this process may map (ulimit -v)\n");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
