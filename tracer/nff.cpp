// NFF parser: a token reader over the input as it is read (and inflated), a
// chunk at a time, and one small function per entity. Every check that can
// fail names the line of the token that broke it, or for a fault of a whole
// entity (a polygon's shape, a material, a second view) the line of its
// keyword; see nff.hpp for the choices made where NFF is silent.
#include "tracer/nff.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <span>
#include <string>
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
// Vertices reserved from a polygon's count, at most: one allocation for the
// usual polygon, and a lying count reserves no more than this.
inline constexpr long long kReserveVertices = 16;

std::string describe(std::string_view token);

// Whitespace-separated tokens; '#' anywhere, even right after a token, ends
// the token and comments out the rest of its line. A line ends at "\n",
// "\r\n" or a lone "\r" (old Mac files). line() is the line of the last token
// read, so an error at end of file points at the line that was cut short.
// The input is read kChunkBytes (256 KB) at a time into one buffer, and a token is a
// view into it: the bytes are looked at once, by a table lookup each, and no
// token is copied. A token cut by the end of a chunk is moved to the front of
// the buffer before the next chunk is read behind it; a token is at most
// kMaxTokenBytes (no NFF number or keyword comes near), so memory stays
// bounded however long the file or its comments and blanks.
class Lexer {
 public:
  Lexer(ByteSource& input, const std::string& source) : input_(input), source_(source) {}

  // The next token, "" at the end; valid until the next call of next() or peek().
  std::string_view next() {
    if (!ahead_) read_token(ahead_token_);
    ahead_ = false;
    if (!ahead_token_.at_end) token_line_ = ahead_token_.line;
    return ahead_token_.text;
  }

  // The token next() would return, without taking it.
  std::string_view peek() {
    if (!ahead_) read_token(ahead_token_);
    ahead_ = true;
    return ahead_token_.text;
  }

  int line() const { return token_line_; }

 private:
  struct Token {
    std::string_view text;
    int line = 0;
    bool at_end = false;
  };

  static constexpr std::size_t kChunkBytes = std::size_t{1} << 18;

  // Byte classes: 1 a blank, 2 also a line end ('\n', '\r'), 4 '#'; 0 a token byte.
  static constexpr std::array<unsigned char, 256> kClass = [] {
    std::array<unsigned char, 256> c{};
    for (unsigned char b : {' ', '\t', '\f', '\v'}) c[b] = 1;
    c['\n'] = c['\r'] = 3;
    c['#'] = 4;
    return c;
  }();
  static unsigned char byte_class(char c) { return kClass[static_cast<unsigned char>(c)]; }

  // Reads the next chunk behind the `keep` bytes from `from` on, which move
  // to the front; false at the end of the input.
  bool refill(std::size_t from, std::size_t keep) {
    if (at_end_) return false;
    std::memmove(buffer_.data(), buffer_.data() + from, keep);
    const std::size_t n = input_.read(buffer_.data() + keep, buffer_.size() - keep);
    at_end_ = n == 0;
    pos_ = keep;
    end_ = keep + n;
    return n > 0;
  }

  // A '\r' followed by '\n' is left to the '\n' to count.
  void skip_blanks() {
    for (;;) {
      if (pos_ == end_ && !refill(0, 0)) return;
      const char c = buffer_[pos_];
      const unsigned char k = byte_class(c);
      if (k == 0) return;
      if (k == 4) {  // a comment, up to the line end (not taken)
        for (;;) {
          while (pos_ < end_ && !(byte_class(buffer_[pos_]) & 2)) ++pos_;
          if (pos_ < end_ || !refill(0, 0)) break;
        }
        continue;
      }
      ++pos_;
      if (c == '\n') {
        ++line_;
      } else if (c == '\r') {
        if (pos_ == end_) refill(0, 0);
        if (pos_ == end_ || buffer_[pos_] != '\n') ++line_;
      }
    }
  }

  void read_token(Token& token) {
    skip_blanks();
    token.line = line_;
    token.at_end = pos_ == end_;
    std::size_t start = pos_;
    for (;;) {
      while (pos_ < end_ && byte_class(buffer_[pos_]) == 0) ++pos_;
      if (pos_ - start > kMaxTokenBytes) too_long(start);
      if (pos_ < end_ || at_end_) break;
      refill(start, pos_ - start);  // the token so far moves to the front
      start = 0;
    }
    token.text = std::string_view(buffer_.data() + start, pos_ - start);
  }

  [[noreturn]] void too_long(std::size_t start) const {
    throw SceneError(source_ + ":" + std::to_string(line_) + ": expected a token of at most " +
                     std::to_string(kMaxTokenBytes) + " bytes, got " +
                     describe(std::string(buffer_.data() + start, kMaxTokenBytes) + "..."));
  }

  ByteSource& input_;
  const std::string& source_;
  std::vector<char> buffer_ = std::vector<char>(kChunkBytes);  // on the heap: a parser may run on a small stack
  std::size_t pos_ = 0, end_ = 0;
  bool at_end_ = false;
  int line_ = 1;
  int token_line_ = 1;
  Token ahead_token_;
  bool ahead_ = false;
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

// The usual NFF number, [-]digits[.digits] with at most 15 significant
// digits, as the exact integer of its digits over a power of ten: both are
// exact doubles, so their quotient is the correctly rounded value, the one
// from_chars gives (Clinger's fast path), for a quarter of its time.
// False for anything else, which from_chars then reads.
bool parse_simple_decimal(std::string_view token, double& value) {
  static constexpr double kPow10[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  const char* p = token.data();
  const char* const end = p + token.size();
  const bool negative = p < end && *p == '-';
  p += negative;
  std::uint64_t digits = 0;
  int count = 0, fraction = 0;
  const char* const int_start = p;
  for (; p < end && unsigned(*p - '0') < 10; ++p, ++count) digits = digits * 10 + unsigned(*p - '0');
  if (p == int_start) return false;
  if (p < end && *p == '.') {
    const char* const frac_start = ++p;
    for (; p < end && unsigned(*p - '0') < 10; ++p, ++count) digits = digits * 10 + unsigned(*p - '0');
    fraction = static_cast<int>(p - frac_start);
    if (fraction == 0) return false;
  }
  if (p != end || count > 15) return false;
  value = double(digits) / kPow10[fraction];
  if (negative) value = -value;
  return true;
}

// A finite double; an underflow is taken as the zero it rounds to.
bool parse_double(std::string_view token, double& value) {
  if (parse_simple_decimal(token, value)) return true;
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
    std::string_view key = lex_.next();
    if (key.empty()) throw SceneError(source_ + ": no NFF entity in the input (is it empty?)");
    for (; !key.empty(); key = lex_.next()) entity(key);
    return finish();
  }

 private:
  // `key` is valid until the entity reads its first token.
  void entity(std::string_view key) {
    const std::string previous_key = entity_key_;
    const int previous_line = entity_line_;
    entity_key_ = key;
    entity_line_ = lex_.line();
    if (key == "v") return view();
    if (key == "b") return void(scene_.background = color("background colour", true));
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
    const std::string_view token = lex_.next();
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

  // A colour whose components are at least 0 and, if `at_most_one`, at most 1
  // (a reflectance; a light's colour is an intensity, unbounded).
  Color color(std::string_view what, bool at_most_one) {
    const Vec3d c = vec3(what);
    for (const double v : {c.x, c.y, c.z})
      if (v < 0 || (at_most_one && v > 1))
        fail_here(std::string(what) + (at_most_one ? " must lie in 0..1" : " must not be negative") +
                  " in each component, got " + format_number(v));
    return {static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z)};
  }

  // A number at least 0, and at most `hi` if given.
  double non_negative(std::string_view what, std::optional<double> hi = std::nullopt) {
    const double v = number(what);
    if (v < 0 || (hi && v > *hi))
      fail_here(std::string(what) + (hi ? " must lie in 0.." + format_number(*hi) : std::string(" must not be negative")) +
                ", got " + format_number(v));
    return v;
  }

  static std::string format_number(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }

  long long integer(std::string_view what, long long lo, long long hi) {
    const std::string_view token = lex_.next();
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
    const std::string_view token = lex_.next();
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
  void check_polygon_shape(std::span<const Vec3d> vertices, const std::string& what);

  // Objects gather in chunks of fixed capacity, moved once into the scene at
  // the end: a growing vector would move every object again at each doubling
  // and hold the old and the new array at once.
  static constexpr std::size_t kChunkObjects = std::size_t{1} << 16;  // 5 MB
  void add(Object&& o) {
    if (chunks_.empty() || chunks_.back().size() == kChunkObjects) {
      chunks_.emplace_back();
      chunks_.back().reserve(kChunkObjects);
    }
    chunks_.back().push_back(std::move(o));
  }
  Scene finish() {
    std::size_t total = 0;
    for (const auto& c : chunks_) total += c.size();
    scene_.objects.reserve(total);
    for (auto& c : chunks_) {
      std::move(c.begin(), c.end(), std::back_inserter(scene_.objects));
      BigVector<Object>().swap(c);  // frees it: the peak is the scene once, not twice
    }
    return std::move(scene_);
  }
  std::vector<BigVector<Object>> chunks_;

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
  if (looks_numeric(lex_.peek())) light.color = color("light colour", false);
  scene_.lights.push_back(light);
}

void Parser::material() {
  Material m;
  m.color = color("material colour", true);
  m.kd = non_negative("Kd");
  m.ks = non_negative("Ks");
  m.shine = non_negative("Phong exponent");
  m.transmittance = non_negative("transmittance", 1.0);
  m.ior = non_negative("index of refraction");
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
  add({c, current_material()});
}

void Parser::sphere() {
  Sphere s;
  s.center = vec3("sphere centre");
  s.radius = number("sphere radius");
  if (s.radius == 0) fail_here("sphere radius is zero");
  add({s, current_material()});
}

// The first three vertices fix the normal (NFF.md), so they must span a
// triangle that turns the way the whole polygon does, judged by its area
// (Newell) normal; and every vertex must lie in the plane, up to the rounding
// of coordinates printed with few digits.
void Parser::check_polygon_shape(std::span<const Vec3d> v, const std::string& what) {
  const Vec3d a = v[1] - v[0], b = v[2] - v[0];
  const Vec3d corner = cross(a, b);
  if (!(length(corner) > 1e-12 * length(a) * length(b)))
    fail_at_entity(what + "'s first three vertices are collinear, so its normal is undefined");
  // A triangle's area normal is its corner's, and three points lie in their
  // plane: nothing more to check (the usual case, so it is worth the test).
  if (v.size() == 3) return;
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
  p.vertices.reserve(static_cast<std::size_t>(std::min(n, kReserveVertices)));
  for (long long i = 0; i < n; ++i) p.vertices.push_back(vec3("polygon vertex"));
  check_polygon_shape(points(p.vertices), "polygon");
  add({std::move(p), current_material()});
}

void Parser::patch() {
  long long n = integer("patch vertex count", 3, 1LL << 40);
  Patch p;
  p.vertices.reserve(static_cast<std::size_t>(std::min(n, kReserveVertices)));
  p.normals.reserve(static_cast<std::size_t>(std::min(n, kReserveVertices)));
  for (long long i = 0; i < n; ++i) {
    p.vertices.push_back(vec3("patch vertex"));
    p.normals.push_back(vec3("patch vertex normal"));
    if (length(p.normals.back()) == 0) fail_here("patch vertex normal has zero length");
  }
  check_polygon_shape(points(p.vertices), "patch");
  add({std::move(p), current_material()});
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
