// Built-in generators against the SPD reference files: same counts by kind,
// lights, materials, camera and bounding box for the same size; the paper's
// named scenes have the paper's polygon counts.
#include "tracer/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <stdexcept>

#include "scene_stats.hpp"
#include "tests/support/paths.hpp"
#include "tracer/nff.hpp"

namespace tracer {
namespace {

using testing::scene_stats;

struct Reference {
  const char* spec;
  const char* file;
};

void PrintTo(const Reference& r, std::ostream* out) { *out << r.spec; }

class GeneratorVsFile : public ::testing::TestWithParam<Reference> {};

// The files print 6 significant digits.
void expect_close(const Vec3d& a, const Vec3d& b, const char* what) {
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(a[axis], b[axis], 2e-5 * std::max(1.0, std::abs(b[axis]))) << what << " axis " << axis;
}

TEST_P(GeneratorVsFile, MatchesCountsCameraAndBounds) {
  Scene generated = generate_scene(GetParam().spec);
  Scene file = load_nff_file(test::shared_scenes() + "/" + GetParam().file);
  auto g = scene_stats(generated), f = scene_stats(file);
  EXPECT_EQ(g.polygons, f.polygons);
  EXPECT_EQ(g.patches, f.patches);
  EXPECT_EQ(g.spheres, f.spheres);
  EXPECT_EQ(g.cones, f.cones);
  EXPECT_EQ(generated.lights.size(), file.lights.size());
  ASSERT_EQ(generated.materials.size(), file.materials.size());
  for (std::size_t i = 0; i < file.materials.size(); ++i) {
    const Color &gc = generated.materials[i].color, &fc = file.materials[i].color;
    EXPECT_NEAR(gc.r, fc.r, 1e-5) << "material " << i;
    EXPECT_NEAR(gc.g, fc.g, 1e-5) << "material " << i;
    EXPECT_NEAR(gc.b, fc.b, 1e-5) << "material " << i;
    EXPECT_NEAR(generated.materials[i].shine, file.materials[i].shine, 1e-3 * file.materials[i].shine);
    EXPECT_DOUBLE_EQ(generated.materials[i].transmittance, file.materials[i].transmittance);
  }
  expect_close(generated.camera.from, file.camera.from, "from");
  expect_close(generated.camera.up, file.camera.up, "up");
  EXPECT_DOUBLE_EQ(generated.camera.hither, file.camera.hither);
  for (std::size_t i = 0; i < file.lights.size(); ++i)
    expect_close(generated.lights[i].position, file.lights[i].position, "light");
  expect_close(g.lo, f.lo, "bounds lo");
  expect_close(g.hi, f.hi, "bounds hi");
}

INSTANTIATE_TEST_SUITE_P(
    SpdFiles, GeneratorVsFile,
    ::testing::Values(Reference{"teapot:7", "teapot-s7.nff.gz"}, Reference{"teapot:8", "teapot-s8.nff.gz"},
                      Reference{"mount:6:t6", "mount-s6-t6.nff.gz"}, Reference{"rings:4:t1", "rings-s4-t1.nff.gz"},
                      Reference{"tetra:9", "tetra-s9.nff.gz"}, Reference{"balls:1", "balls-s1.nff"},
                      Reference{"mount:1", "mount-s1.nff"}, Reference{"rings:1", "rings-s1.nff"},
                      Reference{"tetra:1", "tetra-s1.nff"}, Reference{"gears:1", "gears-s1.nff"},
                      Reference{"tree:1", "tree-s1.nff"}),
    [](const auto& info) {
      std::string name = info.param.spec;
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

TEST(Generators, MountMatchesReferenceVertexForVertex) {
  // The fractal depends on SPD's hash and Gaussian generator: compare heights.
  Scene generated = generate_scene("mount:1");
  Scene file = load_nff_file(test::shared_scenes() + "/mount-s1.nff");
  ASSERT_EQ(generated.objects.size(), file.objects.size());
  for (std::size_t i = 0; i < file.objects.size(); ++i) {
    auto* fp = std::get_if<Polygon>(&file.objects[i].shape);
    if (!fp) continue;
    const auto& gp = std::get<Polygon>(generated.objects[i].shape);
    for (std::size_t k = 0; k < 3; ++k) expect_close(gp.vertices[k], fp->vertices[k], "vertex");
  }
}

TEST(Generators, PaperScenesHaveThePapersPolygonCounts) {
  EXPECT_EQ(generate_scene("teapot").polygon_count(), 4096u);
  EXPECT_EQ(generate_scene("mountain").polygon_count(), 9920u);
  EXPECT_EQ(generate_scene("rings4").polygon_count(), 18001u);
  EXPECT_EQ(generate_scene("tetra9").polygon_count(), 262144u);
}

TEST(Generators, Tetra10HasFourToTheTenTrianglesInTheUnitCube) {
  Scene s = generate_scene("tetra10");
  auto st = scene_stats(s);
  EXPECT_EQ(st.polygons, 1048576u);
  expect_close(st.lo, {-1, -1, -1}, "lo");
  expect_close(st.hi, {1, 1, 1}, "hi");
}

TEST(Generators, TeapotCountFollowsSpdFormula) {
  for (int n : {2, 3, 5}) {
    auto st = scene_stats(generate_scene("teapot:" + std::to_string(n)));
    EXPECT_EQ(st.patches, std::size_t(64 * n * n - 8 * n)) << n;
    EXPECT_EQ(st.polygons, std::size_t(n * n)) << n;
  }
}

TEST(Generators, BallsCountIsSumOfPowersOfNine) {
  EXPECT_EQ(scene_stats(generate_scene("balls:2")).spheres, 91u);
  EXPECT_EQ(scene_stats(generate_scene("balls:3")).spheres, 820u);
}

// Deeper levels have children pointing exactly along -Z, up to rounding.
TEST(Generators, BallsAreAllFinite) {
  for (const Object& o : generate_scene("balls:4").objects) {
    const auto* s = std::get_if<Sphere>(&o.shape);
    if (!s) continue;  // the floor
    ASSERT_TRUE(std::isfinite(s->center.x) && std::isfinite(s->center.y) && std::isfinite(s->center.z) &&
                std::isfinite(s->radius));
  }
}

TEST(Generators, GearsAndTreeCountsFollowSpdFormulas) {
  auto gears = scene_stats(generate_scene("gears:2"));
  EXPECT_EQ(gears.polygons, 1u + 8 * (2 + 144));
  auto tree = scene_stats(generate_scene("tree:3"));
  EXPECT_EQ(tree.spheres, 15u);
  EXPECT_EQ(tree.cones, 15u);
}

TEST(Generators, SceneNameIsTheSpec) { EXPECT_EQ(generate_scene("tetra:2").name, "tetra:2"); }

TEST(Generators, BadSpecsNameTheSpec) {
  for (const char* spec : {"cube", "tetra:0", "tetra:12", "tetra:x", "tetra:3:t0", "tetra:3:q", "tetra9:3",
                           "mount:8", "rings:2:t1:t2", "", "balls:2:t999"}) {
    try {
      generate_scene(spec);
      ADD_FAILURE() << "accepted '" << spec << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("scene '" + std::string(spec) + "': ", 0), 0u) << e.what();
    }
  }
}

TEST(Generators, EveryBuiltinIsListedWithADescriptionAndGenerates) {
  auto list = builtin_scenes();
  ASSERT_GE(list.size(), 9u);
  for (const auto& b : list) {
    EXPECT_FALSE(b.description.empty()) << b.name;
    if (b.name == "tetra10" || b.name == "tetra9") continue;  // covered above
    EXPECT_GT(generate_scene(b.name + (b.name == "teapot" ? ":3" : "")).objects.size(), 0u) << b.name;
  }
}

}  // namespace
}  // namespace tracer
