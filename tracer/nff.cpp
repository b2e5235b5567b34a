// NFF parser: a token reader over the input as it is read (and inflated), a
// chunk at a time, and one small function per entity. Every check that can
// fail names the line of the token that broke it, or for a fault of a whole
// entity (a polygon's shape, a material, a second view) the line of its
// keyword; see nff.hpp for the choices made where NFF is silent.
#include "tracer/nff.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <vector>

namespace tracer {
namespace {

// Bytes of the input in chunks, so that the text is read as it is parsed
// and never held whole: memory follows the scene, not the file.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Up to `size` bytes into `buffer`; 0 only at the end of the input.
  virtual std::size_t read(char* buffer, std::size_t size) = 0;
};

class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::string_view data) : data_(data) {}
  std::size_t read(char* buffer, std::size_t size) override {
    const std::size_t n = std::min(size, data_.size());
    std::copy_n(data_.data(), n, buffer);
    data_.remove_prefix(n);
    return n;
  }

 private:
  std::string_view data_;
};

class StreamSource final : public ByteSource {
 public:
  StreamSource(std::istream& in, const std::string& source) : in_(in), source_(source) {}
  std::size_t read(char* buffer, std::size_t size) override {
    errno = 0;
    try {
      in_.read(buffer, static_cast<std::streamsize>(size));
    } catch (const std::ios_base::failure&) {  // a stream that throws, e.g. on a directory
      throw SceneError(source_ + ": cannot read (is it a regular file?)");
    }
    if (in_.bad()) throw SceneError(source_ + ": read error" + (errno ? std::string(": ") + std::strerror(errno) : ""));
    return static_cast<std::size_t>(in_.gcount());
  }

 private:
  std::istream& in_;
  const std::string& source_;
};

// The first bytes of another source, read ahead to tell gzip by its magic,
// then the rest of it.
class PeekedSource final : public ByteSource {
 public:
  explicit PeekedSource(ByteSource& rest) : rest_(rest) {
    while (head_.size() < 2) {
      char c[2];
      const std::size_t n = rest_.read(c, 2 - head_.size());
      if (n == 0) break;
      head_.append(c, n);
    }
  }
  bool is_gzip() const {
    return head_.size() == 2 && static_cast<unsigned char>(head_[0]) == 0x1f &&
           static_cast<unsigned char>(head_[1]) == 0x8b;
  }
  std::size_t read(char* buffer, std::size_t size) override {
    if (at_ == head_.size()) return rest_.read(buffer, size);
    const std::size_t n = std::min(size, head_.size() - at_);
    std::copy_n(head_.data() + at_, n, buffer);
    at_ += n;
    return n;
  }

 private:
  ByteSource& rest_;
  std::string head_;
  std::size_t at_ = 0;
};

// Inflates a gzip stream as it is read: several members allowed, as gzip(1)
// writes them, and zero bytes after the last (tape or block padding, which
// gzip(1) ignores too); at most kMaxInflatedBytes in all.
class GzipSource final : public ByteSource {
 public:
  GzipSource(ByteSource& raw, const std::string& source) : raw_(raw), source_(source) {
    if (inflateInit2(&zs_, 16 + MAX_WBITS) != Z_OK) throw SceneError(source_ + ": cannot initialise zlib");
  }
  GzipSource(const GzipSource&) = delete;
  GzipSource& operator=(const GzipSource&) = delete;
  ~GzipSource() override { inflateEnd(&zs_); }

  std::size_t read(char* buffer, std::size_t size) override {
    for (;;) {
      if (zs_.avail_in == 0 && !refill()) {
        if (status_ != Z_STREAM_END) throw SceneError(source_ + ": truncated gzip data");
        return 0;
      }
      if (status_ == Z_STREAM_END && !next_member()) continue;
      zs_.next_out = reinterpret_cast<Bytef*>(buffer);
      zs_.avail_out = static_cast<uInt>(size);
      status_ = inflate(&zs_, Z_NO_FLUSH);
      if (status_ != Z_OK && status_ != Z_STREAM_END && !(status_ == Z_BUF_ERROR && zs_.avail_in == 0))
        throw SceneError(source_ + ": corrupt or truncated gzip data");
      if (status_ == Z_BUF_ERROR) status_ = Z_OK;
      const std::size_t produced = size - zs_.avail_out;
      inflated_ += produced;
      if (inflated_ > kMaxInflatedBytes) throw SceneError(source_ + ": gzip data inflates to more than 1 GiB");
      if (produced > 0) return produced;
    }
  }

 private:
  bool refill() {
    const std::size_t n = raw_.read(in_.data(), in_.size());
    zs_.next_in = reinterpret_cast<Bytef*>(in_.data());
    zs_.avail_in = static_cast<uInt>(n);
    return n > 0;
  }

  // After a member's end: false while the input holds zero padding (which
  // it consumes; a member after padding is refused), true once a next
  // member has begun.
  bool next_member() {
    if (padding_ || *zs_.next_in == 0) {
      padding_ = true;
      if (!std::all_of(zs_.next_in, zs_.next_in + zs_.avail_in, [](Bytef b) { return b == 0; }))
        throw SceneError(source_ + ": corrupt or truncated gzip data");
      zs_.avail_in = 0;
      return false;
    }
    inflateReset(&zs_);
    status_ = Z_OK;
    return true;
  }

  ByteSource& raw_;
  const std::string& source_;
  z_stream zs_{};
  int status_ = Z_OK;
  bool padding_ = false;
  std::uint64_t inflated_ = 0;
  std::vector<char> in_ = std::vector<char>(1 << 16);
};

inline constexpr std::size_t kMaxTokenBytes = 1024;

std::string describe(std::string_view token);

// Whitespace-separated tokens; '#' anywhere, even right after a token, ends
// the token and comments out the rest of its line. A line ends at "\n",
// "\r\n" or a lone "\r" (old Mac files). line() is the line of the last token
// read, so an error at end of file points at the line that was cut short.
// The input is read a chunk at a time; a token is at most kMaxTokenBytes
// (no NFF number or keyword comes near), so memory stays bounded however
// long the file or its comments and blanks.
class Lexer {
 public:
  Lexer(ByteSource& input, const std::string& source) : input_(input), source_(source) {}

  // The next token, "" at the end; valid until the next call of next() or peek().
  const std::string& next() {
    if (!ahead_) read_token(ahead_token_);
    ahead_ = false;
    current_ = std::move(ahead_token_.text);
    if (!ahead_token_.at_end) token_line_ = ahead_token_.line;
    return current_;
  }

  // The token next() would return, without taking it.
  const std::string& peek() {
    if (!ahead_) read_token(ahead_token_);
    ahead_ = true;
    return ahead_token_.text;
  }

  int line() const { return token_line_; }

 private:
  struct Token {
    std::string text;
    int line = 0;
    bool at_end = false;
  };

  static bool is_blank(int c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }

  // The next byte, -1 at the end of the input.
  int peek_byte() {
    if (pos_ == end_ && !at_end_) {
      end_ = input_.read(buffer_.data(), buffer_.size());
      pos_ = 0;
      at_end_ = end_ == 0;
    }
    return pos_ < end_ ? static_cast<unsigned char>(buffer_[pos_]) : -1;
  }

  // A '\r' followed by '\n' is left to the '\n' to count.
  void skip_blanks() {
    for (int c = peek_byte(); c >= 0; c = peek_byte()) {
      if (c == '#') {
        while ((c = peek_byte()) >= 0 && c != '\n' && c != '\r') ++pos_;
      } else if (is_blank(c)) {
        ++pos_;
        if (c == '\n' || (c == '\r' && peek_byte() != '\n')) ++line_;
      } else {
        return;
      }
    }
  }

  void read_token(Token& token) {
    skip_blanks();
    token.text.clear();
    token.at_end = peek_byte() < 0;
    token.line = line_;
    for (int c = peek_byte(); c >= 0 && !is_blank(c) && c != '#'; c = peek_byte()) {
      if (token.text.size() == kMaxTokenBytes)
        throw SceneError(source_ + ":" + std::to_string(line_) + ": expected a token of at most " +
                         std::to_string(kMaxTokenBytes) + " bytes, got " + describe(token.text + "..."));
      token.text.push_back(static_cast<char>(c));
      ++pos_;
    }
  }

  ByteSource& input_;
  const std::string& source_;
  std::vector<char> buffer_ = std::vector<char>(1 << 16);  // on the heap: a parser may run on a small stack
  std::size_t pos_ = 0, end_ = 0;
  bool at_end_ = false;
  int line_ = 1;
  int token_line_ = 1;
  Token ahead_token_;
  bool ahead_ = false;
  std::string current_;
};

// How a token is shown in an error: quoted, shortened, bytes escaped.
std::string describe(std::string_view token) {
  if (token.empty()) return "end of file";
  std::string shown = "'";
  for (std::size_t i = 0; i < token.size() && i < 40; ++i) {
    auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      shown += static_cast<char>(c);
    } else {
      const char* hex = "0123456789abcdef";
      shown += {'\\', 'x', hex[c >> 4], hex[c & 15]};
    }
  }
  if (token.size() > 40) shown += "...";
  return shown + "'";
}

// Removes one leading '+' (from_chars takes only '-'); false when what follows
// cannot start an unsigned number, as in "+-1" or "+".
bool strip_plus(std::string_view& token) {
  if (token.empty() || token.front() != '+') return true;
  token.remove_prefix(1);
  return !token.empty() && token.front() != '+' && token.front() != '-';
}

// Whether a decimal number that from_chars found out of range is tiny (it
// underflowed) rather than huge: its first significant digit stands below the
// units place once the exponent is applied. Such numbers are below 1e-300 or
// above 1e300, so the order of magnitude alone decides.
bool underflows(std::string_view token) {
  const std::size_t e = token.find_first_of("eE");
  const std::string_view mantissa = token.substr(0, e);
  long long exponent = 0;
  if (e != std::string_view::npos) {
    std::string_view digits = token.substr(e + 1);
    strip_plus(digits);
    if (std::from_chars(digits.data(), digits.data() + digits.size(), exponent).ec != std::errc())
      exponent = digits.front() == '-' ? -(1LL << 62) : 1LL << 62;  // beyond long long
  }
  const std::size_t point = std::min(mantissa.find('.'), mantissa.size());
  const std::size_t first = mantissa.find_first_of("123456789");
  const long long place = first < point ? static_cast<long long>(point - first) - 1
                                        : -static_cast<long long>(first - point);
  return place + exponent < 0;
}

// A finite double; an underflow is taken as the zero it rounds to.
bool parse_double(std::string_view token, double& value) {
  if (!strip_plus(token)) return false;
  auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (token.empty() || end != token.data() + token.size()) return false;
  if (ec == std::errc::result_out_of_range && underflows(token)) {
    value = token.front() == '-' ? -0.0 : 0.0;
    return true;
  }
  return ec == std::errc() && std::isfinite(value);
}

bool looks_numeric(std::string_view token) {
  double ignored;
  return parse_double(token, ignored);
}

class Parser {
 public:
  Parser(ByteSource& input, const std::string& source) : lex_(input, source), source_(source) {
    scene_.name = source;
  }

  // Input with no entity at all (an empty file, or a pipe that failed) is
  // refused rather than rendered as an empty scene.
  Scene run() {
    std::string key = lex_.next();
    if (key.empty()) throw SceneError(source_ + ": no NFF entity in the input (is it empty?)");
    for (; !key.empty(); key = lex_.next()) entity(key);
    return std::move(scene_);
  }

 private:
  void entity(const std::string& key) {
    const std::string previous_key = entity_key_;
    const int previous_line = entity_line_;
    entity_key_ = key;
    entity_line_ = lex_.line();
    if (key == "v") return view();
    if (key == "b") return void(scene_.background = color("background colour"));
    if (key == "l") return light();
    if (key == "f") return material();
    if (key == "c") return cone();
    if (key == "s") return sphere();
    if (key == "p") return polygon();
    if (key == "pp") return patch();
    fail("an entity keyword (v b l f c s p pp)", key, surplus_hint(previous_key, previous_line, key));
  }

  // A number where a keyword belongs most likely belongs to the entity before.
  static std::string surplus_hint(std::string_view previous_key, int previous_line, std::string_view got) {
    if (previous_key.empty() || !looks_numeric(got)) return "";
    const bool counted = previous_key == "p" || previous_key == "pp";
    return " (does the '" + std::string(previous_key) + "' at line " + std::to_string(previous_line) +
           (counted ? " have more vertices than its count says?)" : " have more numbers than it takes?)");
  }

  [[noreturn]] void fail(std::string_view expected, std::string_view got, const std::string& hint = "") const {
    throw SceneError(source_ + ":" + std::to_string(lex_.line()) + ": expected " +
                     std::string(expected) + ", got " + describe(got) + hint);
  }

  [[noreturn]] void fail_here(const std::string& what) const { fail_at(lex_.line(), what); }

  // For a fault of the entity as a whole: names the line of its keyword.
  [[noreturn]] void fail_at_entity(const std::string& what) const { fail_at(entity_line_, what); }

  [[noreturn]] void fail_at(int line, const std::string& what) const {
    throw SceneError(source_ + ":" + std::to_string(line) + ": " + what);
  }

  double number(std::string_view what) {
    const std::string& token = lex_.next();
    double value;
    if (!parse_double(token, value)) fail(std::string("a finite number (") + std::string(what) + ")", token);
    // The database stores floats: a larger number would become infinite there.
    if (std::abs(value) > std::numeric_limits<float>::max())
      fail(std::string("a number within single precision, at most 3.4e38 (") + std::string(what) + ")", token);
    return value;
  }

  Vec3d vec3(std::string_view what) {
    Vec3d v;
    v.x = number(what);
    v.y = number(what);
    v.z = number(what);
    return v;
  }

  Color color(std::string_view what) {
    Vec3d c = vec3(what);
    return {static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z)};
  }

  long long integer(std::string_view what, long long lo, long long hi) {
    const std::string& token = lex_.next();
    std::string_view digits = token;
    long long value = 0;
    const bool sign_ok = strip_plus(digits);
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (!sign_ok || digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || value < lo ||
        value > hi)
      fail(std::string(what) + " (an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ")", token);
    return value;
  }

  void keyword(std::string_view expected) {
    const std::string& token = lex_.next();
    if (token == expected) return;
    std::string quoted(1, '\'');  // built by append: GCC 12 -O3 warns falsely on "'" + string
    quoted.append(expected).push_back('\'');
    fail(quoted, token);
  }

  void view();
  void light();
  void material();
  void cone();
  void sphere();
  void polygon();
  void patch();
  std::uint32_t current_material();
  void check_polygon_shape(const std::vector<Vec3d>& vertices, const std::string& what);

  Lexer lex_;
  const std::string& source_;
  Scene scene_;
  std::string entity_key_;  // the entity being read, and its keyword's line
  int entity_line_ = 0;
  int view_line_ = 0;  // of the "v" read so far, 0 before it
};

void Parser::view() {
  if (view_line_ != 0)
    fail_at_entity("a second view ('v'); the scene has one camera, already set at line " + std::to_string(view_line_));
  view_line_ = entity_line_;
  Camera& cam = scene_.camera;
  keyword("from");
  cam.from = vec3("eye position");
  keyword("at");
  cam.at = vec3("look-at point");
  if (length(cam.at - cam.from) == 0) fail_here("'at' must differ from 'from'");
  keyword("up");
  cam.up = vec3("up vector");
  if (length(cross(cam.up, cam.at - cam.from)) == 0)
    fail_here("'up' must be non-zero and not parallel to the viewing direction");
  keyword("angle");
  cam.angle_deg = number("field of view in degrees");
  if (!(cam.angle_deg > 0 && cam.angle_deg < 180)) fail_here("'angle' must lie strictly between 0 and 180 degrees");
  keyword("hither");
  cam.hither = number("hither distance");
  if (cam.hither < 0) fail_here("'hither' must not be negative");
  keyword("resolution");
  scene_.resolution_origin = source_ + ":" + std::to_string(lex_.line());
  cam.width = static_cast<int>(integer("image width", 1, kMaxResolution));
  cam.height = static_cast<int>(integer("image height", 1, kMaxResolution));
}

void Parser::light() {
  Light light;
  light.position = vec3("light position");
  if (looks_numeric(lex_.peek())) light.color = color("light colour");
  scene_.lights.push_back(light);
}

void Parser::material() {
  Material m;
  m.color = color("material colour");
  m.kd = number("Kd");
  m.ks = number("Ks");
  m.shine = number("Phong exponent");
  m.transmittance = number("transmittance");
  m.ior = number("index of refraction");
  if (m.transmittance > 0 && !(m.ior > 0))
    fail_at_entity("a transmitting material (T > 0) needs an index of refraction above 0");
  scene_.materials.push_back(m);
}

std::uint32_t Parser::current_material() {
  if (scene_.materials.empty()) scene_.materials.push_back(Material{});
  return static_cast<std::uint32_t>(scene_.materials.size() - 1);
}

void Parser::cone() {
  Cone c;
  c.base = vec3("cone base");
  c.base_radius = number("cone base radius");
  c.apex = vec3("cone apex");
  c.apex_radius = number("cone apex radius");
  if (length(c.apex - c.base) == 0) fail_here("cone base and apex coincide (zero-length axis)");
  if (c.base_radius == 0 && c.apex_radius == 0) fail_here("cone has both radii zero");
  scene_.objects.push_back({c, current_material()});
}

void Parser::sphere() {
  Sphere s;
  s.center = vec3("sphere centre");
  s.radius = number("sphere radius");
  if (s.radius == 0) fail_here("sphere radius is zero");
  scene_.objects.push_back({s, current_material()});
}

// The first three vertices fix the normal (NFF.md), so they must span a
// triangle that turns the way the whole polygon does, judged by its area
// (Newell) normal; and every vertex must lie in the plane, up to the rounding
// of coordinates printed with few digits.
void Parser::check_polygon_shape(const std::vector<Vec3d>& v, const std::string& what) {
  const Vec3d a = v[1] - v[0], b = v[2] - v[0];
  const Vec3d corner = cross(a, b);
  if (!(length(corner) > 1e-12 * length(a) * length(b)))
    fail_at_entity(what + "'s first three vertices are collinear, so its normal is undefined");
  Vec3d area{}, lo = v[0], hi = v[0];
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (i + 1 < v.size()) area += cross(v[i] - v[0], v[i + 1] - v[0]);
    lo = min(lo, v[i]);
    hi = max(hi, v[i]);
  }
  if (length(area) > 0) {
    const Vec3d normal = normalize(area);
    const double tolerance = kPlanarityTolerance * length(hi - lo);
    for (std::size_t i = 1; i < v.size(); ++i)
      if (std::abs(dot(v[i] - v[0], normal)) > tolerance)
        fail_at_entity(what + " is not planar: its vertices do not lie in one plane");
  }
  if (!(dot(corner, area) > 0))
    fail_at_entity(what + "'s first three vertices form a reflex corner (they turn against the " + what +
                   "'s winding), so they cannot fix its normal; start it at a convex corner");
}

void Parser::polygon() {
  long long n = integer("polygon vertex count", 3, 1LL << 40);
  Polygon p;
  for (long long i = 0; i < n; ++i) p.vertices.push_back(vec3("polygon vertex"));
  check_polygon_shape(p.vertices, "polygon");
  scene_.objects.push_back({std::move(p), current_material()});
}

void Parser::patch() {
  long long n = integer("patch vertex count", 3, 1LL << 40);
  Patch p;
  for (long long i = 0; i < n; ++i) {
    p.vertices.push_back(vec3("patch vertex"));
    p.normals.push_back(vec3("patch vertex normal"));
    if (length(p.normals.back()) == 0) fail_here("patch vertex normal has zero length");
  }
  check_polygon_shape(p.vertices, "patch");
  scene_.objects.push_back({std::move(p), current_material()});
}

}  // namespace

namespace {

Scene parse_source(ByteSource& raw, const std::string& source_name) {
  PeekedSource input(raw);
  if (!input.is_gzip()) return Parser(input, source_name).run();
  GzipSource inflated(input, source_name);
  return Parser(inflated, source_name).run();
}

}  // namespace

Scene parse_nff(std::string_view text, const std::string& source_name) {
  MemorySource input(text);
  return parse_source(input, source_name);
}

Scene parse_nff(std::istream& in, const std::string& source_name) {
  StreamSource input(in, source_name);
  return parse_source(input, source_name);
}

Scene load_nff_file(const std::string& path) {
  if (path == "-") return parse_nff(std::cin, "<stdin>");
  errno = 0;
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SceneError(path + ": cannot open: " + (errno ? std::strerror(errno) : "unknown error"));
  return parse_nff(file, path);
}

}  // namespace tracer
