// Topology specification parsing and its one-line errors.
#include "topology/spec.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace topology;

namespace {

std::string error_of(std::string_view spec, std::optional<std::size_t> nodes = std::nullopt) {
  try {
    parse_topology(spec, nodes);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(Spec, ParsesEveryKindWithItsSize) {
  EXPECT_EQ(parse_topology("hypercube:6").size(), 64u);
  EXPECT_EQ(parse_topology("mesh:8x8").kind(), Kind::mesh);
  EXPECT_EQ(parse_topology("torus:4x2").width(), 4u);
  EXPECT_EQ(parse_topology("ring:64").size(), 64u);
  EXPECT_EQ(parse_topology("complete:16").kind(), Kind::complete);
  EXPECT_EQ(parse_topology("mesh:8x4", 32).spec(), "mesh:8x4");
}

TEST(Spec, BareKindTakesNodeCountAndSquarestGrid) {
  EXPECT_EQ(parse_topology("mesh", 16).spec(), "mesh:4x4");
  EXPECT_EQ(parse_topology("torus", 32).spec(), "torus:8x4");
  EXPECT_EQ(parse_topology("mesh", 13).spec(), "mesh:13x1");
  EXPECT_EQ(parse_topology("hypercube", 64).spec(), "hypercube:6");
  EXPECT_EQ(parse_topology("ring", 7).spec(), "ring:7");
}

TEST(Spec, OneNodeWorksForEveryKind) {
  for (const char* kind : {"hypercube", "mesh", "torus", "ring", "complete"})
    EXPECT_EQ(parse_topology(kind, 1).size(), 1u) << kind;
  EXPECT_EQ(parse_topology("hypercube:0").size(), 1u);
}

TEST(Spec, ImpossibleSpecsAreRejectedWithAClearMessage) {
  EXPECT_NE(error_of("hypercube", 48).find("power of two"), std::string::npos);
  EXPECT_NE(error_of("ring:0").find("at least one node"), std::string::npos);
  EXPECT_NE(error_of("ring", 0).find("at least one node"), std::string::npos);
  EXPECT_NE(error_of("complete:5000").find("maximum"), std::string::npos);
  EXPECT_NE(error_of("mesh:128x64").find("maximum"), std::string::npos);
  EXPECT_NE(error_of("hypercube:13").find("4096"), std::string::npos);
  EXPECT_NE(error_of("mesh:8x8", 32).find("the node count asked for is 32"), std::string::npos);
  EXPECT_NE(error_of("banana:4").find("unknown kind 'banana'"), std::string::npos);
  EXPECT_NE(error_of("mesh:8y8").find("WIDTHxHEIGHT"), std::string::npos);
  EXPECT_NE(error_of("ring:abc").find("not a number"), std::string::npos);
  EXPECT_NE(error_of("ring:-3").find("not a number"), std::string::npos);
  EXPECT_NE(error_of("mesh").find("node count"), std::string::npos);
  EXPECT_NE(error_of("").find("unknown kind"), std::string::npos);
  for (auto* spec : {"ring:0", "banana", "mesh:8x", "torus:x4"})
    EXPECT_EQ(error_of(spec).find('\n'), std::string::npos) << spec;
}
