// Option parsing: defaults, values, and one-line errors naming the option.
#include "app/render/options.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/support/command_line.hpp"

namespace app {
namespace {

using test::parse;

std::string error_of(std::vector<const char*> args) {
  try {
    parse(std::move(args));
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(Options, DefaultsRenderTheTeapotToTeapotPng) {
  const Options o = parse({});
  EXPECT_EQ(o.scene, "teapot");
  EXPECT_EQ(o.output, "teapot.png");
  EXPECT_EQ(o.page_size, 1024u);
  EXPECT_EQ(o.accel, tracer::Accel::bvh);
  EXPECT_EQ(o.bvh_layout, tracer::BvhLayout::treelet);
  EXPECT_EQ(o.max_depth, 5);
  EXPECT_FALSE(o.spd_procedure);
}

TEST(Options, ParsesEveryValue) {
  const Options o = parse({"scene.nff", "-o", "x.ppm", "--stats", "s.json", "--spd-procedure",
                           "--accel", "grid", "--bvh-layout", "depth-first", "--page-size", "4096", "--max-depth", "3",
                           "--width", "64", "--height", "32", "--tessellate", "2", "--quiet"});
  EXPECT_EQ(o.scene, "scene.nff");
  EXPECT_EQ(o.output, "x.ppm");
  EXPECT_EQ(o.stats_path, "s.json");
  EXPECT_TRUE(o.spd_procedure);
  EXPECT_EQ(o.accel, tracer::Accel::grid);
  EXPECT_EQ(o.bvh_layout, tracer::BvhLayout::depth_first);
  EXPECT_EQ(o.page_size, 4096u);
  EXPECT_EQ(o.max_depth, 3);
  EXPECT_EQ(o.width, 64);
  EXPECT_EQ(o.height, 32);
  EXPECT_EQ(o.tessellate, 2);
  EXPECT_TRUE(o.quiet);
}

TEST(Options, BadValuesNameTheOption) {
  EXPECT_NE(error_of({"--accel", "kdtree"}).find("--accel"), std::string::npos);
  EXPECT_NE(error_of({"--bvh-layout", "veb"}).find("--bvh-layout"), std::string::npos);
  EXPECT_NE(error_of({"--page-size", "1000"}).find("--page-size"), std::string::npos);
  EXPECT_NE(error_of({"--page-size", "128"}).find("--page-size"), std::string::npos);
  EXPECT_NE(error_of({"--max-depth", "0"}).find("--max-depth"), std::string::npos);
  EXPECT_NE(error_of({"--width", "-3"}).find("--width"), std::string::npos);
  EXPECT_NE(error_of({"--page-size", "-1024"}).find("--page-size: page size -1024"), std::string::npos);
  EXPECT_NE(error_of({"--page-size", "abc"}).find("page-size"), std::string::npos);
  EXPECT_NE(error_of({"--frobnicate"}).find("frobnicate"), std::string::npos);
}

// A file option names a file of the kind its writer makes, given before the
// render rather than found wanting after it.
TEST(Options, OutputNamesMustNameAFileOfTheirKind) {
  EXPECT_EQ(error_of({"--machine-svg", "m.png"}), "--machine-svg: expected a .svg file name, got 'm.png'");
  EXPECT_EQ(error_of({"--timeline", "t"}), "--timeline: expected a .svg file name, got 't'");
  EXPECT_EQ(error_of({"--ownership", "notes.txt"}),
            "--ownership: expected a .png or .ppm file name, got 'notes.txt'");
  EXPECT_EQ(error_of({"--report", "r.pdf"}), "--report: expected a .html or .htm file name, got 'r.pdf'");
  EXPECT_EQ(error_of({"-o", "image.jpg"}), "--output: expected a .png or .ppm file name, got 'image.jpg'");
  for (const char* option : {"--stats", "--tiles", "--machine-svg", "--ownership", "--report", "-o"})
    EXPECT_NE(error_of({option, ""}).find(": needs a file name"), std::string::npos) << option;
  const Options o = parse({"-o", "A.PPM", "--machine-svg", "dir.d/M.SVG", "--report", "r.htm", "--stats", "s"});
  EXPECT_EQ(o.pictures.report_html, "r.htm");
  EXPECT_EQ(o.stats_path, "s");
}

// Options that would change nothing in the run asked for are errors.
TEST(Options, OptionsThatWouldChangeNothingAreErrors) {
  EXPECT_EQ(error_of({"--schedule", "static", "--grain", "64"}),
            "--grain: the static schedule hands out fixed shares, not tiles of a grain");
  EXPECT_EQ(error_of({"--timing", "virtual", "--compare-serial"}),
            "--compare-serial: a virtual-time run always reports speedup against the 1-node machine");
  EXPECT_EQ(parse({"--schedule", "static"}).machine.farming.schedule, nodes::Schedule::static_split);
  EXPECT_TRUE(parse({"--compare-serial"}).compare_serial);
}

// 0 stands for "the scene's own" inside Options, but a user who writes 0
// asked for something that does not exist.
TEST(Options, AnExplicitZeroSizeOrTessellationIsAnError) {
  EXPECT_EQ(error_of({"--width", "0"}), "--width: expected 1..16384, got 0");
  EXPECT_EQ(error_of({"--height", "0"}), "--height: expected 1..16384, got 0");
  EXPECT_EQ(error_of({"--tessellate", "0"}), "--tessellate: expected 1..64, got 0");
  const Options o = parse({"--width", "16384", "--height", "1", "--tessellate", "64"});
  EXPECT_EQ(o.width, 16384);
  EXPECT_EQ(o.height, 1);
  EXPECT_EQ(o.tessellate, 64);
}

// The machine's bounds are its own (nodes::check_options); the parser only
// refuses what the field's type cannot hold, and names the option either way.
TEST(Options, TheMachinesBoundsAreCheckedByTheMachine) {
  EXPECT_EQ(error_of({"--grain", "0"}), "--grain: must be at least 1, got 0");
  EXPECT_EQ(error_of({"--grain", "-3"}), "--grain: must not be negative, got -3");
  EXPECT_EQ(error_of({"--workers-per-node", "0"}), "--workers-per-node: must be at least 1, got 0");
  EXPECT_EQ(error_of({"--workers-per-node", "65"}), "--workers-per-node: must be at most 64, got 65");
  EXPECT_EQ(error_of({"--workers-per-node", "3000000000"}), "--workers-per-node: is too large, got 3000000000");
  EXPECT_EQ(error_of({"--prefetch", "4"}).rfind("--prefetch: must be at most 3, got 4", 0), 0u);
  const Options o = parse({"--grain", "1048576", "--workers-per-node", "64", "--prefetch", "3"});
  EXPECT_EQ(o.machine.farming.grain, nodes::max_grain);
  EXPECT_EQ(o.machine.shape.workers_per_node, nodes::max_workers_per_node);
  EXPECT_EQ(o.machine.farming.prefetch, 3);
}

// --single has no machine to give these to; ignoring them would mislead.
TEST(Options, MachineOptionsWithSingleAreErrors) {
  for (const char* option : {"--nodes", "--cache-pages", "--grain", "--trace-routes"})
    EXPECT_EQ(error_of({"--single", option, "4"}),
              std::string(option) + ": an option of the machine, but --single renders without one");
  for (const auto& [option, value] : {std::pair{"--topology", "ring"}, {"--timing", "virtual"},
                                      {"--machine-svg", "m.svg"}, {"--report", "r.html"}, {"--cost", "box=1us"}})
    EXPECT_NE(error_of({"--single", option, value}).find(std::string(option) + ": an option of the machine"),
              std::string::npos);
  EXPECT_NE(error_of({"--single", "--compare-serial"}).find("--compare-serial"), std::string::npos);
  const Options o = parse({"--single", "--width", "8", "--shadow-rays", "all"});
  EXPECT_TRUE(o.single);
  // --threads is the one machine option the single-process renderer takes.
  EXPECT_EQ(parse({"--single", "--threads", "3"}).machine.threads.count, 3u);
}

TEST(Options, HelpAndVersionAreActions) {
  EXPECT_EQ(parse({"--help"}).action, Options::Action::help);
  EXPECT_EQ(parse({"--version"}).action, Options::Action::version);
  EXPECT_NE(usage_text().find("--page-size"), std::string::npos);
}

TEST(Options, OutputNameFollowsTheScene) {
  EXPECT_EQ(default_output("tetra:9"), "tetra-9.png");
  EXPECT_EQ(default_output("/a/b/rings-s4-t1.nff.gz"), "rings-s4-t1.png");
  EXPECT_EQ(default_output("-"), "stdin.png");
}

}  // namespace
}  // namespace app
