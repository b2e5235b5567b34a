// NFF parser: a token reader over the whole (inflated) text, and one small
// function per entity. Every check that can fail names the line of the token
// that broke it; see nff.hpp for the choices made where NFF is silent.
#include "tracer/nff.hpp"

#include <zlib.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>

namespace tracer {
namespace {

bool is_gzip(std::string_view data) {
  return data.size() >= 2 && static_cast<unsigned char>(data[0]) == 0x1f &&
         static_cast<unsigned char>(data[1]) == 0x8b;
}

// Inflates a gzip stream (several members allowed, as gzip(1) writes them).
std::string inflate_gzip(std::string_view data, const std::string& source) {
  z_stream zs{};
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) throw SceneError(source + ": cannot initialise zlib");
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  zs.avail_in = static_cast<uInt>(data.size());
  std::string out;
  char chunk[1 << 16];
  int status = Z_OK;
  while (status != Z_STREAM_END || zs.avail_in > 0) {
    if (status == Z_STREAM_END) inflateReset(&zs);  // next gzip member
    zs.next_out = reinterpret_cast<Bytef*>(chunk);
    zs.avail_out = sizeof chunk;
    status = inflate(&zs, Z_NO_FLUSH);
    if (status != Z_OK && status != Z_STREAM_END) {
      inflateEnd(&zs);
      throw SceneError(source + ": corrupt or truncated gzip data");
    }
    out.append(chunk, sizeof chunk - zs.avail_out);
    if (out.size() > kMaxInflatedBytes) {
      inflateEnd(&zs);
      throw SceneError(source + ": gzip data inflates to more than 1 GiB");
    }
    if (status == Z_OK && zs.avail_in == 0 && zs.avail_out != 0) {
      inflateEnd(&zs);
      throw SceneError(source + ": truncated gzip data");
    }
  }
  inflateEnd(&zs);
  return out;
}

// Whitespace-separated tokens; '#' at the start of a token comments out the
// rest of its line. line() is the line of the last token read, so an error at
// end of file points at the line that was cut short.
class Lexer {
 public:
  explicit Lexer(std::string_view text) : text_(text) {}

  std::string_view next() {
    skip_blanks();
    if (pos_ < text_.size()) token_line_ = line_;
    std::size_t start = pos_;
    while (pos_ < text_.size() && !is_blank(text_[pos_])) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  std::string_view peek() {
    Lexer saved = *this;
    std::string_view token = next();
    *this = saved;
    return token;
  }

  int line() const { return token_line_; }

 private:
  static bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }

  void skip_blanks() {
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else if (is_blank(c)) {
        line_ += c == '\n';
        ++pos_;
      } else {
        return;
      }
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int token_line_ = 1;
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

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size() && std::isfinite(value);
}

bool looks_numeric(std::string_view token) {
  double ignored;
  return parse_double(token, ignored);
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& source) : lex_(text), source_(source) {
    scene_.name = source;
  }

  // Input with no entity at all (an empty file, or a pipe that failed) is
  // refused rather than rendered as an empty scene.
  Scene run() {
    std::string_view key = lex_.next();
    if (key.empty()) throw SceneError(source_ + ": no NFF entity in the input (is it empty?)");
    for (; !key.empty(); key = lex_.next()) entity(key);
    return std::move(scene_);
  }

 private:
  void entity(std::string_view key) {
    if (key == "v") return view();
    if (key == "b") return void(scene_.background = color("background colour"));
    if (key == "l") return light();
    if (key == "f") return material();
    if (key == "c") return cone();
    if (key == "s") return sphere();
    if (key == "p") return polygon();
    if (key == "pp") return patch();
    fail("an entity keyword (v b l f c s p pp)", key);
  }

  [[noreturn]] void fail(std::string_view expected, std::string_view got) const {
    throw SceneError(source_ + ":" + std::to_string(lex_.line()) + ": expected " +
                     std::string(expected) + ", got " + describe(got));
  }

  [[noreturn]] void fail_here(const std::string& what) const {
    throw SceneError(source_ + ":" + std::to_string(lex_.line()) + ": " + what);
  }

  double number(std::string_view what) {
    std::string_view token = lex_.next();
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
    std::string_view token = lex_.next();
    long long value = 0;
    auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (token.empty() || ec != std::errc() || end != token.data() + token.size() || value < lo || value > hi)
      fail(std::string(what) + " (an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ")", token);
    return value;
  }

  void keyword(std::string_view expected) {
    std::string_view token = lex_.next();
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
  void check_first_corner(const std::vector<Vec3d>& vertices);

  Lexer lex_;
  const std::string& source_;
  Scene scene_;
};

void Parser::view() {
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

// The first three vertices fix the normal, so they must span a triangle.
void Parser::check_first_corner(const std::vector<Vec3d>& v) {
  Vec3d a = v[1] - v[0], b = v[2] - v[0];
  double area = length(cross(a, b));
  if (!(area > 1e-12 * length(a) * length(b)))
    fail_here("polygon's first three vertices are collinear, so its normal is undefined");
}

void Parser::polygon() {
  long long n = integer("polygon vertex count", 3, 1LL << 40);
  Polygon p;
  for (long long i = 0; i < n; ++i) p.vertices.push_back(vec3("polygon vertex"));
  check_first_corner(p.vertices);
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
  check_first_corner(p.vertices);
  scene_.objects.push_back({std::move(p), current_material()});
}

}  // namespace

Scene parse_nff(std::string_view text, const std::string& source_name) {
  if (is_gzip(text)) {
    std::string inflated = inflate_gzip(text, source_name);
    return Parser(inflated, source_name).run();
  }
  return Parser(text, source_name).run();
}

Scene parse_nff(std::istream& in, const std::string& source_name) {
  std::string text;
  try {
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::ios_base::failure&) {  // e.g. the path is a directory
    throw SceneError(source_name + ": cannot read (is it a regular file?)");
  }
  if (in.bad()) throw SceneError(source_name + ": read error");
  return parse_nff(std::string_view(text), source_name);
}

Scene load_nff_file(const std::string& path) {
  if (path == "-") return parse_nff(std::cin, "<stdin>");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SceneError(path + ": cannot open file");
  return parse_nff(file, path);
}

}  // namespace tracer
