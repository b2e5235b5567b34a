// NFF (Neutral File Format, as written by Eric Haines' SPD generators) input.
// The parser reads tokens, not lines, and either returns a Scene meeting every
// invariant listed in scene.hpp or throws SceneError with one line
// "SOURCE:LINE: expected ..., got ...". It never pre-allocates from a count
// read from the input, so a lying count costs nothing but an error at EOF.
// Where the format is silent, the choices made are listed at parse_nff().
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
inline constexpr double kPlanarityTolerance = 1e-3;

// Choices where the format is silent:
//  - objects before any "f" get a default material (white, Kd 1, nothing else);
//  - a polygon or patch whose first three vertices are collinear (or
//    coincide), or form a reflex corner (turning against the winding of the
//    whole polygon, by its area normal), is an error, since those vertices fix
//    its normal;
//  - a polygon or patch with a vertex farther than kPlanarityTolerance times
//    its bounding-box diagonal from its plane (through its first vertex, with
//    its area normal) is an error: it is not planar;
//  - a transmitting material (T > 0) needs an index of refraction above 0;
//  - a second "v" is an error (a scene has one camera);
//  - a cone may have one zero radius (a true cone), not both;
//  - resolution is capped at kMaxResolution per axis;
//  - numbers and counts may carry one leading '+'; a number too small for a
//    double is read as zero, one too large is an error;
//  - a lone CR ends a line (old Mac files), as do LF and CRLF;
//  - gzip input (by magic bytes) is inflated as it is read, up to
//    kMaxInflatedBytes; zero bytes after it (block padding) are ignored.
//
// Parses NFF text (or gzip-compressed NFF text) held in memory.
Scene parse_nff(std::string_view text, const std::string& source_name);

// Parses the stream as it reads it, a chunk at a time: the memory taken
// follows the scene, not the size of the file (blanks and comments cost
// nothing). A token is at most 1024 bytes.
Scene parse_nff(std::istream& in, const std::string& source_name);

// Loads a file; "-" reads standard input. Throws SceneError if it can't be read.
Scene load_nff_file(const std::string& path);

}  // namespace tracer
