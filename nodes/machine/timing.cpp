// Cost models, profiles and the virtual-time hooks of the machine (see timing.hpp).
#include "nodes/machine/timing.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "tracer/generators.hpp"
#include "tracer/render.hpp"

namespace nodes {

namespace {

using Seconds = std::chrono::duration<double>;

// Relative costs of one operation on an 80386/80387 node, in units of a box
// test (a slab test: six multiplies and compares): a triangle test is about
// twice that, shading a ray (lighting, spawning secondaries) about five, a
// software page-table look-up about a fifth. Only their ratio matters here:
// `unit` is fitted to Teapot on one node (Table 2: 3h12mn2s at 512x512).
constexpr double ipsc2_box = 1.0, ipsc2_prim = 2.0, ipsc2_shade = 5.0, ipsc2_page = 0.2;
// Fitted so that Teapot at 512x512 on one node with the paper's 3072 pages
// of cache takes 11522 s, 3h12mn2s (docs/paper.md gives the sweep that fits it).
constexpr double ipsc2_unit = 371.437e-6;
// The virtual clock counts picoseconds in 64 bits: about 106 days.
constexpr double max_virtual_seconds = 9e6;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// A number with an optional unit from `units` after it (spaces between are
// allowed: "175us", "2.8 MB/s"), scaled to the base unit. Throws
// std::invalid_argument with the reason.
template <std::size_t N>
double with_unit(const std::string& text, const std::pair<const char*, double> (&units)[N], const char* what) {
  const std::string number = trim(text);
  double v = 0;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), v);
  if (ec == std::errc::result_out_of_range) throw std::invalid_argument("out of range");
  if (ec != std::errc()) throw std::invalid_argument(std::string("not a ") + what);
  const std::string unit = trim(std::string(end, number.data() + number.size()));
  if (unit.empty()) return v;
  for (const auto& [name, scale] : units)
    if (unit == name) return v * scale;
  throw std::invalid_argument(std::string("unknown ") + what + " unit '" + unit + "'");
}

double time_seconds(const std::string& text) {
  static const std::pair<const char*, double> units[] = {
      {"ps", 1e-12}, {"ns", 1e-9}, {"us", 1e-6}, {"ms", 1e-3}, {"s", 1.0}};
  return with_unit(text, units, "time");
}

double bytes_per_second(const std::string& text) {
  static const std::pair<const char*, double> units[] = {
      {"B/s", 1.0}, {"KB/s", 1e3}, {"MB/s", 1e6}, {"GB/s", 1e9}};
  return with_unit(text, units, "bandwidth");
}

// Sets one key; throws std::invalid_argument with a short reason.
void set_cost(CostModel& m, const std::string& key, const std::string& value) {
  double v = 0;
  try {
    v = key == "bw" || key == "bandwidth" ? bytes_per_second(value) : time_seconds(value);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bad value '" + value + "' for " + key + " (" + e.what() + ")");
  }
  if (!(v >= 0) || !std::isfinite(v)) throw std::invalid_argument(key + " must be a finite value >= 0");
  if (key == "unit") m.unit = v;
  else if (key == "box") m.box = v;
  else if (key == "prim") m.prim = v;
  else if (key == "shade") m.shade = v;
  else if (key == "page") m.page = v;
  else if (key == "serve") m.serve = v;
  else if (key == "msg") m.msg = v;
  else if (key == "hop") m.hop = v;
  else if (key == "bw" || key == "bandwidth") m.bandwidth = v;
  else throw std::invalid_argument("unknown cost '" + key + "' (box, prim, shade, page, serve, msg, hop, bw, unit)");
}

// Seconds per weighted operation of this machine's tracer: a small scene
// rendered once, its time divided by its ipsc2-weighted operation count.
double calibrate_compute() {
  const tracer::Scene scene = tracer::generate_scene("teapot");
  tracer::Database db = tracer::build_database(scene, {});
  db.header.camera.width = 96;
  db.header.camera.height = 96;
  tracer::InMemoryPageSource pages(db);
  tracer::RayStats stats;
  const auto t0 = std::chrono::steady_clock::now();
  tracer::render_frame(db.header, pages, {}, stats);
  const double seconds = Seconds(std::chrono::steady_clock::now() - t0).count();
  CostModel weights = ipsc2_profile();
  weights.unit = 1.0;
  return seconds / weights.compute_seconds(stats);
}

// Seconds per message handed through one csp channel (a ping-pong on this
// thread): the cost of one store-and-forward stage of the simulated network.
double calibrate_hop() {
  constexpr int rounds = 20000;
  csp::Runtime rt(1);
  csp::Channel<int> ping("ping"), pong("pong");
  rt.spawn("echo", 0, [&] {
    for (int i = 0; i < rounds; ++i) pong.writer().write(ping.reader().read());
  });
  double seconds = 0;
  rt.spawn("timer", 0, [&] {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < rounds; ++i) {
      ping.writer().write(i);
      pong.reader().read();
    }
    seconds = Seconds(std::chrono::steady_clock::now() - t0).count();
  });
  rt.run();
  return seconds / (2.0 * rounds);
}

double calibrate_bandwidth() {
  std::vector<std::byte> from(1 << 20, std::byte{1}), to(1 << 20);
  constexpr int rounds = 64;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < rounds; ++i) {
    std::memcpy(to.data(), from.data(), from.size());
    from[static_cast<std::size_t>(i)] = to[static_cast<std::size_t>(i) + 1];  // keep the copies alive
  }
  const double seconds = Seconds(std::chrono::steady_clock::now() - t0).count();
  return seconds > 0 ? double(from.size()) * rounds / seconds : 0.0;
}

}  // namespace

double CostModel::compute_seconds(const tracer::RayStats& rays) const {
  return unit * (box * double(rays.box_tests) + prim * double(rays.prim_tests) + shade * double(rays.rays()) +
                 page * double(rays.page_calls));
}

LinkModel CostModel::link_model() const {
  return LinkModel{std::chrono::nanoseconds(std::llround(hop * 1e9)), bandwidth};
}

std::string CostModel::describe() const {
  std::ostringstream out;
  out << name << ": unit=" << unit << " box=" << box << " prim=" << prim << " shade=" << shade << " page=" << page
      << " serve=" << serve << "s msg=" << msg << "s hop=" << hop << "s bw=";
  if (bandwidth > 0) out << bandwidth << "B/s";
  else out << "unlimited";
  return out.str();
}

CostModel ipsc2_profile() {
  CostModel m;
  m.name = "ipsc2";
  m.unit = ipsc2_unit;
  m.box = ipsc2_box;
  m.prim = ipsc2_prim;
  m.shade = ipsc2_shade;
  m.page = ipsc2_page;
  m.serve = 150e-6;
  m.msg = 175e-6;
  m.hop = 175e-6;
  m.bandwidth = 2.8e6;
  return m;
}

CostModel native_profile() {
  CostModel m = ipsc2_profile();
  m.name = "native";
  m.unit = calibrate_compute();
  m.hop = calibrate_hop();
  m.serve = m.hop;
  m.msg = 0;  // a channel hand-over costs the sender and receiver nothing beyond the hop
  m.bandwidth = calibrate_bandwidth();
  return m;
}

CostModel profile_named(const std::string& name) {
  if (name == "ipsc2") return ipsc2_profile();
  if (name == "native") return native_profile();
  throw std::invalid_argument("unknown machine profile '" + name + "' (ipsc2, native)");
}

void apply_costs(CostModel& model, const std::string& spec, const std::string& where) {
  std::istringstream items(spec);
  for (std::string item; std::getline(items, item, ',');) {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument(where + ": expected key=value, got '" + item + "'");
    try {
      set_cost(model, trim(item.substr(0, eq)), trim(item.substr(eq + 1)));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(where + ": " + e.what());
    }
  }
}

CostModel read_profile_file(const std::string& path) {
  // A directory opens, then reads as nothing: an empty profile in silence.
  if (std::filesystem::is_directory(path)) throw std::runtime_error(path + ": is a directory, not a profile");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open profile");
  CostModel model;
  model.name = path;
  std::map<std::string, int> set_on_line;  // key -> line it was set on
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string where = path + ":" + std::to_string(number);
    line = trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw std::runtime_error(where + ": expected 'key = value', got '" + line + "'");
    const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    // A key set twice, or a base profile after costs it would reset, is a mistake.
    const std::string name = key == "bandwidth" ? "bw" : key;
    if (const auto [at, first] = set_on_line.try_emplace(name, number); !first)
      throw std::runtime_error(where + ": " + key + " is already set on line " + std::to_string(at->second));
    if (key == "profile" && set_on_line.size() > 1)
      throw std::runtime_error(where + ": 'profile' must come before the costs it is the base of");
    try {
      if (key == "profile") {
        model = profile_named(value);
        model.name = path;
      } else {
        set_cost(model, key, value);
      }
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
  }
  return model;
}

ComputeMeter::ComputeMeter(const CostModel& model, const tracer::RayStats& rays, std::shared_ptr<NodeCpu> cpu)
    : model_(model), rays_(rays), cpu_(std::move(cpu)) {}

// Messages of one tile: the work that brings it, and the result that also
// asks for the next.
constexpr std::uint64_t tile_messages = 2;
// Messages of one page request on the requesting side: the request and the page.
constexpr std::uint64_t request_messages = 2;

void ComputeMeter::charge() {
  messages_ += tile_messages;
  advance_clock();
}

void ComputeMeter::charge_page_request() {
  messages_ += request_messages;
  advance_clock();
}

void ComputeMeter::advance_clock() {
  // Work is cumulative in the counters: price the totals, then give the clock
  // the difference, so rounding to picoseconds never accumulates.
  charged_ = model_.compute_seconds(rays_) + model_.msg * double(messages_) + cpu_->stolen / cpu_->workers;
  if (!(charged_ < max_virtual_seconds))
    throw std::overflow_error("virtual time beyond " + std::to_string(max_virtual_seconds) +
                              " s: the cost model is far too slow");
  const auto total_ps = static_cast<std::int64_t>(std::llround(charged_ * 1e12));
  const std::int64_t step = total_ps - charged_ps_;
  charged_ps_ = total_ps;
  if (step <= 0) return;
  const std::int64_t now = csp::this_process::now().count();
  cpu_->busy_until_ps = std::max(now, cpu_->busy_until_ps) + step;
  csp::this_process::advance(csp::VirtualDuration(cpu_->busy_until_ps - now));
}

MachineTiming::MachineTiming(CostModel model, int nodes)
    : model_(std::move(model)), record_(std::make_shared<csp::VirtualTimeRecord>()) {
  for (int n = 0; n < nodes; ++n) cpus_.push_back(std::make_shared<NodeCpu>());
}

csp::RuntimeOptions MachineTiming::runtime_options(std::size_t stack_size) const {
  csp::RuntimeOptions o;
  o.threads = 1;
  o.stack_size = stack_size;
  o.scheduler = csp::virtual_time_scheduler(record_);
  return o;
}

ComputeMeter& MachineTiming::add_meter(int node, const tracer::RayStats& rays) {
  const auto& cpu = cpus_[static_cast<std::size_t>(node)];
  ++cpu->workers;
  meters_.push_back(std::make_unique<ComputeMeter>(model_, rays, cpu));
  return *meters_.back();
}

std::unique_ptr<ChargingObserver> MachineTiming::charges(int node, const std::vector<const tracer::RayStats*>& workers) {
  std::vector<ComputeMeter*> meters;
  for (const tracer::RayStats* rays : workers) meters.push_back(&add_meter(node, *rays));
  return std::make_unique<ChargingObserver>(std::move(meters));
}

std::function<void()> MachineTiming::serve_hook(int node) {
  // The handler, and the request it receives and the page it sends.
  const double busy = model_.serve + double(request_messages) * model_.msg;
  return [busy, cpu = cpus_[static_cast<std::size_t>(node)]] {
    cpu->stolen += busy;
    csp::this_process::advance(csp::VirtualDuration(static_cast<std::int64_t>(std::llround(busy * 1e12))));
  };
}

double MachineTiming::predicted_seconds() const { return double(record_->end().count()) * 1e-12; }

double MachineTiming::compute_seconds() const {
  double total = 0;
  for (const auto& m : meters_) total += m->charged_seconds();
  return total;
}

}  // namespace nodes
