// Pictures of a machine run: owners recorded for every pixel match the
// per-node pixel counts, the machine SVG is well formed with one node per
// processor, and the HTML page links only files it wrote.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "app/experiments/machine_pictures.hpp"
#include "app/viz/colour.hpp"
#include "topology/spec.hpp"
#include "tests/app/viz/xml_check.hpp"
#include "tracer/generators.hpp"

namespace {

namespace fs = std::filesystem;

nodes::MachineResult small_run(bool corners, bool record_tiles = true) {
  tracer::Scene scene = tracer::generate_scene("teapot:2");
  scene.camera.width = 12;
  scene.camera.height = 10;
  nodes::MachineOptions options;
  options.topology = topology::parse_topology("mesh:2x2");
  options.threads.count = 1;
  options.trace.spd_procedure = corners;
  options.timing = nodes::ipsc2_profile();
  options.observe.record_tiles = record_tiles;
  return nodes::run_machine(tracer::build_database(scene, {}), options);
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MachinePictures, OwnersAgreeWithPixelsComputedPerNode) {
  const auto run = small_run(false);
  const auto owners = app::pixel_owners(run.report, 12, 10);
  ASSERT_EQ(owners.size(), 120u);
  std::vector<std::uint64_t> counted(4);
  for (auto o : owners) ++counted.at(o);
  for (std::size_t n = 0; n < 4; ++n) EXPECT_EQ(counted[n], run.report.per_node[n].work.items) << "node " << n;
}

TEST(MachinePictures, CornerSamplesGiveOnePixelOwnerEach) {
  const auto run = small_run(true);
  EXPECT_EQ(run.report.owners.size(), 13u * 11u);
  EXPECT_EQ(app::pixel_owners(run.report, 12, 10).size(), 120u);
  EXPECT_THROW(app::pixel_owners(run.report, 20, 20), std::invalid_argument);
}

TEST(MachinePictures, WritesWellFormedSvgAndAPageLinkingOnlyItsFiles) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmpray_machine_pictures";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto run = small_run(false);
  const app::PictureFiles files{dir / "machine.svg", dir / "owners.png", dir / "run.html", dir / "tiles.svg"};
  const auto written = app::write_machine_pictures(files, {.title = "teapot on a 2x2 mesh"}, run.image, run.report);
  // What the command line checks for clashes before the render is what is written.
  std::vector<fs::path> announced;
  for (const auto& [option, path] : app::picture_outputs(files)) announced.push_back(path);
  EXPECT_EQ(written, announced);

  const auto svg = viz::test::check_xml(read(files.machine_svg));
  ASSERT_TRUE(svg.ok) << svg.error;
  EXPECT_EQ(viz::machine_node_places(app::machine_drawing(run.report)).size(), 4u);
  // The ownership picture: the 12 x 10 image enlarged, with its key.
  EXPECT_GT(tracer::read_png(files.ownership_png.string()).width, 12 * 20);
  const auto tiles = viz::test::check_xml(read(files.timeline_svg));
  ASSERT_TRUE(tiles.ok) << tiles.error;
  EXPECT_EQ(viz::timeline_bars(app::timeline(run.report)).size(), run.report.farmer.tiles);  // few tiles: none merged

  const std::string html = read(files.report_html);
  EXPECT_NE(html.find("predicted synthesis time"), std::string::npos);
  // The page is titled by the scene; its section says what it shows.
  EXPECT_NE(html.find("<h1>teapot on a 2x2 mesh</h1>"), std::string::npos);
  EXPECT_NE(html.find("<h2>The run on mesh:2x2</h2>"), std::string::npos);
  // It stands alone: the image and the ownership picture are in it, and it
  // references no file, so the directory holds only what was asked for.
  const std::regex link(R"((?:src|href)=\"([^\"#][^\"]*)\")");
  int images = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), link); it != std::sregex_iterator(); ++it, ++images)
    EXPECT_TRUE((*it)[1].str().starts_with("data:image/png;base64,")) << (*it)[1].str().substr(0, 60);
  EXPECT_EQ(images, 2);
  std::set<fs::path> on_disk;
  for (const auto& entry : fs::directory_iterator(dir)) on_disk.insert(entry.path());
  EXPECT_EQ(on_disk, std::set<fs::path>(written.begin(), written.end()));
  EXPECT_NE(html.find("when each processor traced each tile"), std::string::npos);
  EXPECT_NE(html.find("<caption>Per node</caption>"), std::string::npos);
  EXPECT_NE(html.find("<caption>Hops by packet kind</caption>"), std::string::npos);
  EXPECT_EQ(html.find("Per MPI rank"), std::string::npos);  // one process: no ranks' table
  // The ownership picture's key: one swatch per processor, in its colour.
  for (int n = 0; n < 4; ++n)
    EXPECT_NE(html.find("<li style=\"background:" + viz::hex(viz::node_colour(n))), std::string::npos) << n;
}

TEST(MachinePictures, APictureThatCannotBeWrittenTakesTheOthersWithIt) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmpray_machine_pictures_failed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto run = small_run(false);
  const app::PictureFiles files{dir / "machine.svg", dir / "owners.png", {}, dir / "missing" / "tiles.svg"};
  EXPECT_THROW(app::write_machine_pictures(files, {.title = "teapot"}, run.image, run.report), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
}

// The page goes last; when it cannot be put in place (a directory stands
// at its path) the pictures written before it go too.
TEST(MachinePictures, AReportThatCannotBeWrittenTakesThePicturesWithIt) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmpray_machine_report_failed";
  fs::remove_all(dir);
  fs::create_directories(dir / "r.html");
  const auto run = small_run(false);
  const app::PictureFiles files{dir / "machine.svg", {}, dir / "r.html", {}};
  EXPECT_THROW(app::write_machine_pictures(files, {.title = "teapot"}, run.image, run.report), std::runtime_error);
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"r.html"});
}

TEST(MachinePictures, TimelineNeedsARunThatRecordedItsTiles) {
  const fs::path dir = fs::path(::testing::TempDir()) / "vmpray_machine_pictures_untimed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto run = small_run(false, false);
  app::PictureFiles files;
  files.timeline_svg = dir / "tiles.svg";
  EXPECT_THROW(app::write_machine_pictures(files, {.title = "teapot"}, run.image, run.report), std::invalid_argument);
  EXPECT_FALSE(fs::exists(files.timeline_svg));
}

TEST(MachinePictures, TablesHaveARowPerNodeAndPerKindThatAddUpToTheRun) {
  const auto run = small_run(false);
  auto report = run.report;
  auto tables = app::machine_tables(report);
  ASSERT_EQ(tables.size(), 2u);
  ASSERT_EQ(tables[0].rows.size(), 4u);
  std::uint64_t pixels = 0;
  for (const auto& row : tables[0].rows) {
    ASSERT_EQ(row.size(), tables[0].header.size());
    pixels += std::stoull(row[1]);
  }
  EXPECT_EQ(pixels, 120u);
  ASSERT_EQ(tables[1].rows.size(), report.network.hops_by_kind.size() + 1);
  std::uint64_t packets = 0;
  for (std::size_t i = 0; i + 1 < tables[1].rows.size(); ++i) packets += std::stoull(tables[1].rows[i][1]);
  EXPECT_EQ(tables[1].rows.back()[0], "all");
  EXPECT_EQ(std::to_string(packets), tables[1].rows.back()[1]);
  // A split run adds the ranks' table, a row per rank.
  report.ranks.resize(2);
  report.ranks[0].node_count = 2;
  report.ranks[1].rank = 1;
  report.ranks[1].first_node = 2;
  report.ranks[1].node_count = 2;
  report.cut_links = 2;
  tables = app::machine_tables(report);
  ASSERT_EQ(tables.size(), 3u);
  EXPECT_EQ(tables[2].caption, "Per MPI rank (2 links cut)");
  ASSERT_EQ(tables[2].rows.size(), 2u);
  EXPECT_EQ(tables[2].rows[1][1], "2-3");
}

}  // namespace
