// NFF (Neutral File Format, as written by Eric Haines' SPD generators) input.
// The parser reads tokens, not lines, and either returns a Scene meeting every
// invariant listed in scene.hpp or throws SceneError with one line
// "SOURCE:LINE: expected ..., got ...". It never pre-allocates from a count
// read from the input, so a lying count costs nothing but an error at EOF.
// Choices where the format is silent:
//  - objects before any "f" get a default material (white, Kd 1, nothing else);
//  - a polygon whose first three vertices are collinear (or coincide) is an
//    error, since those vertices fix its normal;
//  - a cone may have one zero radius (a true cone), not both;
//  - resolution is capped at kMaxResolution per axis;
//  - gzip input (by magic bytes) is inflated transparently, up to
//    kMaxInflatedBytes.
#pragma once

#include <cstddef>
#include <istream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "tracer/scene.hpp"

namespace tracer {

// A malformed scene: what() is one line naming source and line.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr int kMaxResolution = 16384;
inline constexpr std::size_t kMaxInflatedBytes = std::size_t{1} << 30;

// Parses NFF text (or gzip-compressed NFF text) held in memory.
Scene parse_nff(std::string_view text, const std::string& source_name);

// Reads the whole stream, then parses it as above.
Scene parse_nff(std::istream& in, const std::string& source_name);

// Loads a file; "-" reads standard input. Throws SceneError if it can't be read.
Scene load_nff_file(const std::string& path);

}  // namespace tracer
