// NFF parser: the reference SPD files parse with the right counts, the
// format's token-level rules hold, and each malformed input gives one clear
// error naming its line.
#include "tracer/nff.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <istream>
#include <ostream>
#include <sstream>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

#include "scene_stats.hpp"
#include "tests/support/paths.hpp"

namespace tracer {
namespace {

using testing::scene_stats;

struct ReferenceFile {
  const char* name;
  std::size_t polygons, patches, spheres, cones, lights, materials;
  Vec3d lo, hi;
};

void PrintTo(const ReferenceFile& f, std::ostream* out) { *out << f.name; }

class NffReference : public ::testing::TestWithParam<ReferenceFile> {};

TEST_P(NffReference, ParsesWithExpectedCountsAndBounds) {
  const ReferenceFile& ref = GetParam();
  Scene scene = load_nff_file(test::shared_scenes() + "/" + ref.name);
  auto s = scene_stats(scene);
  EXPECT_EQ(s.polygons, ref.polygons);
  EXPECT_EQ(s.patches, ref.patches);
  EXPECT_EQ(s.spheres, ref.spheres);
  EXPECT_EQ(s.cones, ref.cones);
  EXPECT_EQ(scene.lights.size(), ref.lights);
  EXPECT_EQ(scene.materials.size(), ref.materials);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(s.lo[axis], ref.lo[axis], 1e-6) << "axis " << axis;
    EXPECT_NEAR(s.hi[axis], ref.hi[axis], 1e-6) << "axis " << axis;
  }
  EXPECT_EQ(scene.camera.width, 512);
  EXPECT_EQ(scene.camera.height, 512);
}

INSTANTIATE_TEST_SUITE_P(
    SpdFiles, NffReference,
    ::testing::Values(
        ReferenceFile{"balls-s1.nff", 1, 0, 10, 0, 3, 2, {-12, -12, -0.5}, {12, 12, 0.710998}},
        ReferenceFile{"gears-s1.nff", 147, 0, 0, 0, 5, 2, {-2, -2, 0}, {2, 2, 1}},
        ReferenceFile{"mount-s1.nff", 8, 0, 4, 0, 1, 2, {-1.15961, -1, -0.5481}, {1, 1.15961, 1.37821}},
        ReferenceFile{"rings-s1.nff", 1, 0, 30, 30, 3, 7, {-4.27965, 1.65358, -2.77965}, {2.27965, 5.22625, 3.77965}},
        ReferenceFile{"tetra-s1.nff", 4, 0, 0, 0, 1, 1, {-1, -1, -1}, {1, 1, 1}},
        ReferenceFile{"tree-s1.nff", 1, 0, 3, 3, 7, 2, {-50, -50, 0}, {50, 50, 1.701755}},
        ReferenceFile{"mount-s6-t6.nff.gz", 8192, 1728, 0, 0, 1, 2, {-1.15961, -1, -0.702953}, {1, 1.15961, 1.37821}},
        ReferenceFile{"rings-s4-t1.nff.gz", 1, 18000, 0, 0, 3, 181, {-7.5593, 1.65721, -6.0593}, {5.5593, 13.0656, 7.0593}},
        ReferenceFile{"teapot-s7.nff.gz", 49, 3080, 0, 0, 2, 3, {-4, -4, 0}, {4, 4, 3.15}},
        ReferenceFile{"teapot-s8.nff.gz", 64, 4032, 0, 0, 2, 3, {-4, -4, 0}, {4, 4, 3.15}},
        ReferenceFile{"tetra-s9.nff.gz", 262144, 0, 0, 0, 1, 1, {-1, -1, -1}, {1, 1, 1}}),
    [](const auto& info) {
      std::string name = info.param.name;
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

Scene parse(const std::string& text) { return parse_nff(std::string_view(text), "t.nff"); }

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

const char* kView =
    "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.5\nresolution 64 32\n";

TEST(Nff, ReadsCameraBackgroundLightAndMaterial) {
  Scene s = parse(std::string(kView) + "b 0.1 0.2 0.3\nl 1 2 3\nf 1 0.5 0 0.7 0.3 20 0.1 1.5\ns 0 0 0 1\n");
  EXPECT_EQ(s.camera.from, (Vec3d{0, 0, 5}));
  EXPECT_EQ(s.camera.up, (Vec3d{0, 1, 0}));
  EXPECT_DOUBLE_EQ(s.camera.angle_deg, 40);
  EXPECT_DOUBLE_EQ(s.camera.hither, 0.5);
  EXPECT_EQ(s.camera.width, 64);
  EXPECT_EQ(s.camera.height, 32);
  EXPECT_EQ(s.background, (Color{0.1f, 0.2f, 0.3f}));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].color, (Color{1, 1, 1}));
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_DOUBLE_EQ(s.materials[0].shine, 20);
  EXPECT_DOUBLE_EQ(s.materials[0].ior, 1.5);
}

TEST(Nff, ReadsTokensNotLines) {
  Scene s = parse("c\n0 0 0 1\n0 0 2 0.5\np 3 0 0 0 1 0 0 0 1 0 s 0 0 0\n 2");
  ASSERT_EQ(s.objects.size(), 3u);
  auto& cone = std::get<Cone>(s.objects[0].shape);
  EXPECT_EQ(cone.apex, (Vec3d{0, 0, 2}));
  EXPECT_DOUBLE_EQ(cone.apex_radius, 0.5);
  EXPECT_EQ(std::get<Polygon>(s.objects[1].shape).vertices.size(), 3u);
  EXPECT_DOUBLE_EQ(std::get<Sphere>(s.objects[2].shape).radius, 2);
}

TEST(Nff, LightColourIsOptional) {
  Scene s = parse("l 1 2 3 0.5 0.25 1\nl 4 5 6\ns 0 0 0 1");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].color, (Color{0.5f, 0.25f, 1}));
  EXPECT_EQ(s.lights[1].position, (Vec3d{4, 5, 6}));
  EXPECT_EQ(s.lights[1].color, (Color{1, 1, 1}));
}

TEST(Nff, ObjectsBeforeAnyMaterialGetTheDefault) {
  Scene s = parse("s 0 0 0 1\nf 1 0 0 1 0 1 0 1\ns 1 1 1 1\n");
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].color, (Color{1, 1, 1}));
  EXPECT_DOUBLE_EQ(s.materials[0].kd, 1);
  EXPECT_EQ(s.objects[0].material, 0u);
  EXPECT_EQ(s.objects[1].material, 1u);
}

TEST(Nff, CommentsRunToEndOfLine) {
  Scene s = parse("# a comment s 1 1 1 1\ns 0 0 0 1 # another\n#\n");
  EXPECT_EQ(s.objects.size(), 1u);
}

TEST(Nff, HashEndsATokenAndStartsAComment) {
  Scene s = parse("s 0 0 0 1#note 5\ns 0 0 0 2#");
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_DOUBLE_EQ(std::get<Sphere>(s.objects[0].shape).radius, 1);
  EXPECT_DOUBLE_EQ(std::get<Sphere>(s.objects[1].shape).radius, 2);
}

TEST(Nff, LoneCarriageReturnEndsALineAndAComment) {
  Scene s = parse("# old Mac file\rs 0 0 0 1\r# more\rs 0 0 0 2");
  EXPECT_EQ(s.objects.size(), 2u);
}

TEST(Nff, NumbersAndCountsMayHaveALeadingPlus) {
  Scene s = parse("v from 0 0 1 at 0 0 0 up 0 1 0 angle +45 hither 1 resolution +32 +16\n"
                  "p +3 +1 0 0 0 1 0 0 0 1\n");
  EXPECT_EQ(s.camera.width, 32);
  EXPECT_EQ(s.camera.height, 16);
  EXPECT_EQ(std::get<Polygon>(s.objects[0].shape).vertices.size(), 3u);
}

TEST(Nff, UnderflowingNumbersBecomeZeroOrDenormal) {
  Scene s = parse("s 1e-400 -2e-324 1e-99999999999999999999 1\ns 0.00000000001e-310 0 0 1");
  const Vec3d c = std::get<Sphere>(s.objects[0].shape).center;
  EXPECT_EQ(c, (Vec3d{0, 0, 0}));
  EXPECT_TRUE(std::signbit(c.y));
  EXPECT_GT(std::get<Sphere>(s.objects[1].shape).center.x, 0);  // a denormal
}

TEST(Nff, OpaqueMaterialMayHaveZeroIndexOfRefraction) {
  Scene s = parse("f 1 1 1 1 0 1 0 0\ns 0 0 0 1");
  EXPECT_DOUBLE_EQ(s.materials[0].ior, 0);
}

TEST(Nff, ALightMayBeBrighterThanOneAMaterialExactlyOne) {
  Scene s = parse("l 0 0 5 4 4 4\nf 1 1 1 1 1 100 1 1.5\nb 1 1 1\ns 0 0 0 1");
  EXPECT_FLOAT_EQ(s.lights[0].color.r, 4.0f);
  EXPECT_DOUBLE_EQ(s.materials[0].transmittance, 1.0);
}

TEST(Nff, NearlyPlanarPolygonIsAccepted) {
  Scene s = parse("p 4\n0 0 0\n1 0 0\n1 1 0.001\n0 1 0\n");
  EXPECT_EQ(std::get<Polygon>(s.objects[0].shape).vertices.size(), 4u);
}

TEST(Nff, NegativeRadiusIsLegal) {
  Scene s = parse("s 0 0 0 -1");
  EXPECT_DOUBLE_EQ(std::get<Sphere>(s.objects[0].shape).radius, -1);
}

TEST(Nff, NonConvexPolygonWithManyVerticesKeepsThemAll) {
  Scene s = parse("p 5\n0 0 0\n2 0 0\n2 2 0\n1 0.5 0\n0 2 0\n");
  EXPECT_EQ(std::get<Polygon>(s.objects[0].shape).vertices.size(), 5u);
}

std::string gzip(const std::string& text) {
  z_stream zs{};
  deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&zs, text.size()) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  zs.avail_in = static_cast<uInt>(text.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

TEST(Nff, GzipIsDetectedByMagicBytes) {
  std::istringstream in(gzip("s 0 0 0 1\ns 1 1 1 2\n"));
  Scene s = parse_nff(in, "x.nff");
  EXPECT_EQ(s.objects.size(), 2u);
}

TEST(Nff, GzipFollowedByZeroPaddingLoads) {
  Scene s = parse(gzip("s 0 0 0 1\n") + std::string(512, '\0'));
  EXPECT_EQ(s.objects.size(), 1u);
}

TEST(NffError, GzipFollowedByOtherBytesIsAnError) {
  EXPECT_EQ(error_of(gzip("s 0 0 0 1\n") + std::string(8, '\0') + "junk").rfind("t.nff: ", 0), 0u);
}

TEST(NffError, TruncatedGzipNamesTheSource) {
  std::string z = gzip(std::string(5000, ' ') + "s 0 0 0 1\n");
  EXPECT_NE(error_of(z.substr(0, z.size() / 2)).find("t.nff: "), std::string::npos);
}

TEST(NffError, MissingFileNamesIt) {
  EXPECT_THROW(load_nff_file("/nonexistent/scene.nff"), SceneError);
}

TEST(NffError, DirectoryIsASceneErrorNotACrash) {
  EXPECT_THROW(load_nff_file(::testing::TempDir()), SceneError);
}

struct BadInput {
  const char* label;
  std::string text;
  std::string expected;  // the whole message must start with this
};

void PrintTo(const BadInput& b, std::ostream* out) { *out << b.label; }

class NffBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(NffBadInput, GivesOneLineErrorWithLineNumber) {
  std::string message = error_of(GetParam().text);
  EXPECT_EQ(message.rfind(GetParam().expected, 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, NffBadInput,
    ::testing::Values(
        BadInput{"TruncatedLine", "s 0 0 0 1\ns 0 0", "t.nff:2: expected a finite number (sphere centre), got end of file"},
        BadInput{"BadNumber", "\n\ns 0 0 x2 1", "t.nff:3: expected a finite number (sphere centre), got 'x2'"},
        BadInput{"TrailingGarbageInNumber", "s 0 0 0 1.5.2", "t.nff:1: expected a finite number (sphere radius), got '1.5.2'"},
        BadInput{"UnknownKeyword", "s 0 0 0 1\nsphere 1 2 3", "t.nff:2: expected an entity keyword (v b l f c s p pp), got 'sphere'"},
        BadInput{"TooFewVertices", "p 2\n0 0 0\n1 0 0\n", "t.nff:1: expected polygon vertex count (an integer in 3.."},
        BadInput{"NegativeCount", "pp -4\n", "t.nff:1: expected patch vertex count (an integer in 3.."},
        BadInput{"CountLargerThanFile", "p 1000000000000\n0 0 0\n1 0 0\n", "t.nff:3: expected a finite number (polygon vertex), got end of file"},
        BadInput{"NaN", "s 0 nan 0 1", "t.nff:1: expected a finite number (sphere centre), got 'nan'"},
        BadInput{"Empty", "", "t.nff: no NFF entity in the input (is it empty?)"},
        BadInput{"OnlyComments", "# nothing\n\n# here\n", "t.nff: no NFF entity in the input (is it empty?)"},
        BadInput{"BeyondFloat", "p 3\n0 0 0\n1e39 0 0\n0 1 0\n",
                 "t.nff:3: expected a number within single precision, at most 3.4e38 (polygon vertex), got '1e39'"},
        BadInput{"Infinity", "l 0 0 -inf", "t.nff:1: expected a finite number (light position), got '-inf'"},
        BadInput{"Overflow", "s 0 0 0 1e999", "t.nff:1: expected a finite number (sphere radius), got '1e999'"},
        BadInput{"ZeroRadius", "\ns 1 2 3 0", "t.nff:2: sphere radius is zero"},
        BadInput{"ZeroUp", "v from 0 0 1 at 0 0 0 up 0 0 0 angle 45 hither 1 resolution 8 8", "t.nff:1: 'up' must be non-zero"},
        BadInput{"UpAlongView", "v from 0 0 1 at 0 0 0 up 0 0 3 angle 45 hither 1 resolution 8 8", "t.nff:1: 'up' must be non-zero"},
        BadInput{"FromEqualsAt", "v\nfrom 1 1 1\nat 1 1 1\n", "t.nff:3: 'at' must differ from 'from'"},
        BadInput{"MissingViewField", "v\nfrom 0 0 1\nat 0 0 0\nangle 45", "t.nff:4: expected 'up', got 'angle'"},
        BadInput{"HugeResolution", "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 100000 8", "t.nff:1: expected image width (an integer in 1..16384), got '100000'"},
        BadInput{"BadAngle", "v from 0 0 1 at 0 0 0 up 0 1 0 angle 180 hither 1 resolution 8 8", "t.nff:1: 'angle' must lie"},
        BadInput{"ZeroConeAxis", "c 1 1 1 0.5\n1 1 1 0.5", "t.nff:2: cone base and apex coincide"},
        BadInput{"CollinearFirstCorner", "p 4\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n", "t.nff:1: polygon's first three vertices are collinear"},
        BadInput{"CollinearPatchCorner", "\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0 1\n", "t.nff:2: patch's first three vertices are collinear"},
        BadInput{"ReflexFirstCorner", "p 5\n2 2 0\n1 0.5 0\n0 2 0\n0 0 0\n2 0 0\n",
                 "t.nff:1: polygon's first three vertices form a reflex corner (they turn against the polygon's winding)"},
        BadInput{"NonPlanarPolygon", "s 0 0 0 1\np 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0.01\n", "t.nff:2: polygon is not planar: its vertices do not lie in one plane"},
        BadInput{"NonPlanarPatch", "pp 4\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0.5 0 0 1\n0 1 0 0 0 1\n", "t.nff:1: patch is not planar: its vertices do not lie in one plane"},
        BadInput{"PlusMinus", "s 0 0 0 +-1", "t.nff:1: expected a finite number (sphere radius), got '+-1'"},
        BadInput{"LonePlus", "s 0 0 0 +", "t.nff:1: expected a finite number (sphere radius), got '+'"},
        BadInput{"PlusMinusCount", "p +-3", "t.nff:1: expected polygon vertex count (an integer in 3.."},
        BadInput{"DanglingExponent", "s 0 0 0 1e-", "t.nff:1: expected a finite number (sphere radius), got '1e-'"},
        BadInput{"HugeExponent", "s 0 0 0 1e99999999999999999999", "t.nff:1: expected a finite number (sphere radius), got '1e99999999999999999999'"},
        BadInput{"CrOnlyLines", "s 0 0 0 1\r\rs 0 0 x 1", "t.nff:3: expected a finite number (sphere centre), got 'x'"},
        BadInput{"CrLfIsOneLineEnd", "s 0 0 0 1\r\n\r\ns 0 0 x 1", "t.nff:3: expected a finite number (sphere centre), got 'x'"},
        BadInput{"CommentEndsAtCr", "s 0 0 0 1 # note\rs 0 0 x 1", "t.nff:2: expected a finite number (sphere centre), got 'x'"},
        BadInput{"TransmittingWithoutIor", "s 0 0 0 1\nf 1 1 1 1 0 1 0.5\n0\n", "t.nff:2: a transmitting material (T > 0) needs an index of refraction above 0"},
        BadInput{"SecondView", "v from 0 0 1 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8\ns 0 0 0 1\n"
                 "v from 0 0 2 at 0 0 0 up 0 1 0 angle 45 hither 1 resolution 8 8\n",
                 "t.nff:3: a second view ('v'); the scene has one camera, already set at line 1"},
        BadInput{"MoreVerticesThanCount", "p 3\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n",
                 "t.nff:5: expected an entity keyword (v b l f c s p pp), got '0' "
                 "(does the 'p' at line 1 have more vertices than its count says?)"},
        BadInput{"MoreNumbersThanFields", "b 0 0 0\ns 0 0 0 1 2\n",
                 "t.nff:2: expected an entity keyword (v b l f c s p pp), got '2' "
                 "(does the 's' at line 2 have more numbers than it takes?)"},
        BadInput{"ZeroPatchNormal", "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n", "t.nff:3: patch vertex normal has zero length"},
        BadInput{"HugeMaterialColour", "f 1e30 1 1 1 0 1 0 0\ns 0 0 0 1", "t.nff:1: material colour must lie in 0..1 in each component, got 1e+30"},
        BadInput{"NegativeBackground", "b 0 -0.5 0\n", "t.nff:1: background colour must lie in 0..1 in each component, got -0.5"},
        BadInput{"NegativeLightColour", "l 0 0 0 1 -1 1\n", "t.nff:1: light colour must not be negative in each component, got -1"},
        BadInput{"NegativeIor", "f 1 1 1 1 0 1 0\n-1\n", "t.nff:2: index of refraction must not be negative, got -1"},
        BadInput{"NegativeKd", "f 1 1 1 -1 0 1 0 0\n", "t.nff:1: Kd must not be negative, got -1"},
        BadInput{"TransmittanceAboveOne", "f 1 1 1 1 0 1 2 1.5\n", "t.nff:1: transmittance must lie in 0..1, got 2"},
        BadInput{"ShortMaterial", "f 1 1 1 1 0 1 0\ns 0 0 0 1", "t.nff:2: expected a finite number (index of refraction), got 's'"},
        BadInput{"BinaryGarbage", std::string("s 0 0 0 1\n\x01\x02\xff", 13), "t.nff:2: expected an entity keyword (v b l f c s p pp), got '\\x01\\x02\\xff'"}),
    [](const auto& info) { return std::string(info.param.label); });

}  // namespace
}  // namespace tracer

namespace tracer {
namespace {

// A stream of `text` followed by `blanks` spaces, made as it is read, that
// counts the bytes handed out: a parser holding the input whole would take
// them all before the first token.
class BlankTail : public std::streambuf {
 public:
  BlankTail(std::string text, std::uint64_t blanks) : text_(std::move(text)), blanks_(blanks) {}
  std::uint64_t handed_out() const { return handed_out_; }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    std::size_t n = 0;
    while (n < sizeof chunk_ && at_ < text_.size()) chunk_[n++] = text_[at_++];
    while (n < sizeof chunk_ && blanks_ > 0) chunk_[n++] = ' ', --blanks_;
    if (n == 0) return traits_type::eof();
    handed_out_ += n;
    setg(chunk_, chunk_, chunk_ + n);
    return traits_type::to_int_type(chunk_[0]);
  }

 private:
  std::string text_;
  std::size_t at_ = 0;
  std::uint64_t blanks_;
  std::uint64_t handed_out_ = 0;
  char chunk_[4096];
};

// The scene is parsed as it is read: an error in its first line is found
// having read little more than a chunk of the gigabyte after it, which is
// never held in memory.
TEST(NffStream, AnErrorIsFoundWithoutReadingTheRestOfTheInput) {
  BlankTail source("s 0 0 0 zero\n", std::uint64_t{1} << 30);
  std::istream in(&source);
  try {
    parse_nff(in, "big.nff");
    ADD_FAILURE() << "parsed";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "big.nff:1: expected a finite number (sphere radius), got 'zero'");
  }
  EXPECT_LT(source.handed_out(), std::uint64_t{1} << 20);
}

// Blanks and comments far longer than a chunk, in plain text and across
// gzip members, cost nothing and keep the line count.
TEST(NffStream, LongBlanksAndCommentsAcrossChunksAndMembers) {
  const std::string first = std::string(200000, ' ') + "# " + std::string(150000, 'c') + "\ns 0 0 0 1\n";
  const std::string second = std::string(100000, '\n') + "s 1 1 1 2\n";
  EXPECT_EQ(parse_nff(first + second, "t.nff").objects.size(), 2u);
  EXPECT_EQ(parse_nff(gzip(first) + gzip(second) + std::string(70000, '\0'), "t.nff").objects.size(), 2u);
  try {
    parse_nff(gzip(first) + gzip(second + "s 2 2 2 zero\n"), "t.nff");
    ADD_FAILURE() << "parsed";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "t.nff:100004: expected a finite number (sphere radius), got 'zero'");
  }
}

TEST(NffError, ATokenLongerThan1024BytesNamesItsLine) {
  try {
    parse_nff("s 0 0 0 1\ns " + std::string(5000, '1') + " 0 0 1\n", "t.nff");
    ADD_FAILURE() << "parsed";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("t.nff:2: expected a token of at most 1024 bytes, got '1111", 0), 0u)
        << e.what();
  }
}

// Plain decimals are read by a shortcut of their own; every number must come
// out as std::from_chars reads it, bit for bit, on both sides of the
// shortcut's limits (15 significant digits, a point with digits on both sides).
TEST(Nff, NumbersAreReadAsFromCharsReadsThem) {
  const std::vector<std::string> numbers = {"-0.996094",
                                            "0.1",
                                            "1",
                                            "-0",
                                            "0.000000000000001",
                                            "123456789012345",
                                            "1234567890123456",
                                            "9007199254740993",
                                            "0.30000000000000004",
                                            "5.",
                                            ".5",
                                            "-.5",
                                            "1e3",
                                            "2.5E-3",
                                            "00000000000000000001.5",
                                            "3.141592653589793",
                                            "-999999999999999.9",
                                            "0.123456789012345"};
  for (const std::string& n : numbers) {
    const Scene s = parse_nff("s " + n + " 0 0 1\n", "t.nff");
    const double got = std::get<Sphere>(s.objects[0].shape).center.x;
    double want = 0;
    const std::string_view digits = n;
    std::from_chars(digits.data(), digits.data() + digits.size(), want);
    EXPECT_EQ(std::signbit(got), std::signbit(want)) << n;
    EXPECT_EQ(got, want) << n;
  }
}

// The input is read in chunks of 256 KB: a token cut by a chunk's end, at
// every offset across it, reads as the whole token.
TEST(NffStream, TokensCutByAChunkEndReadWhole) {
  constexpr std::size_t kChunk = std::size_t{1} << 18;
  const std::string sphere = "s 0.125 -2.5 3.75 1.0625\n";
  for (std::size_t back = 1; back <= sphere.size(); ++back) {
    const std::string text = std::string(kChunk - back, ' ') + sphere;
    const Scene s = parse_nff(text, "t.nff");
    ASSERT_EQ(s.objects.size(), 1u) << back;
    const Sphere& got = std::get<Sphere>(s.objects[0].shape);
    EXPECT_EQ(got.center.x, 0.125) << back;
    EXPECT_EQ(got.center.y, -2.5) << back;
    EXPECT_EQ(got.center.z, 3.75) << back;
    EXPECT_EQ(got.radius, 1.0625) << back;
  }
}

}  // namespace
}  // namespace tracer
