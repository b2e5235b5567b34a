// Human-readable and JSON forms of MachineSummary, and the tile timeline as
// CSV; see machine_summary.hpp.
#include "app/render/machine_summary.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <tuple>
#include <vector>

#include "app/render/cpu_count.hpp"
#include "app/render/wording.hpp"
#include "nodes/machine/messages.hpp"
#include "topology/topology.hpp"

namespace app {
namespace {

std::string kind_name(std::uint8_t kind) { return std::string(nodes::message_kind_name(kind)); }

// Up to 16 nodes fit a table; beyond that only the least and most loaded.
constexpr std::size_t kTableNodes = 16;

void print_node_row(std::ostream& out, std::size_t n, const nodes::NodeReport& r) {
  out << "  " << std::setw(5) << n << std::setw(10) << r.work.items << std::setw(12)
      << r.work.rays.rays() << std::setw(12) << r.svm.accesses() << std::setw(10) << r.svm.misses
      << std::setw(11) << r.svm.miss_ratio() << std::setw(10) << r.served.pages_served << "\n";
}

void print_per_node(std::ostream& out, const nodes::MachineReport& r, const char* items) {
  out << "per node       " << items << " imbalance " << r.item_imbalance() << ", rays imbalance "
      << r.ray_imbalance() << " (max/mean)\n"
      << "  " << std::setw(5) << "node" << std::setw(10) << items << std::setw(12) << "rays"
      << std::setw(12) << "accesses" << std::setw(10) << "misses" << std::setw(11) << "miss ratio"
      << std::setw(10) << "served" << "\n";
  const auto& nodes = r.per_node;
  if (nodes.size() <= kTableNodes) {
    for (std::size_t n = 0; n < nodes.size(); ++n) print_node_row(out, n, nodes[n]);
    return;
  }
  const auto by_rays = [](const nodes::NodeReport& a, const nodes::NodeReport& b) {
    return a.work.rays.rays() < b.work.rays.rays();
  };
  const auto least = std::min_element(nodes.begin(), nodes.end(), by_rays);
  const auto most = std::max_element(nodes.begin(), nodes.end(), by_rays);
  out << "  fewest rays:\n";
  print_node_row(out, static_cast<std::size_t>(least - nodes.begin()), *least);
  out << "  most rays:\n";
  print_node_row(out, static_cast<std::size_t>(most - nodes.begin()), *most);
}

Json json_svm(const nodes::SvmStats& s) {
  return {{"accesses", s.accesses()}, {"local_hits", s.own_hits}, {"cache_hits", s.cache_hits},
          {"misses", s.misses},       {"coalesced", s.coalesced}, {"miss_ratio", s.miss_ratio()}};
}

// The cache a node actually has: what was asked for, capped at the pages it
// does not own; the largest over the nodes.
std::uint32_t largest_cache(const nodes::MachineReport& r) {
  std::uint32_t largest = 0;
  for (const nodes::NodeReport& node : r.per_node) largest = std::max(largest, node.cache_capacity);
  return largest;
}

Json json_per_node(const nodes::MachineReport& r) {
  Json nodes = Json::array();
  for (std::size_t n = 0; n < r.per_node.size(); ++n) {
    const nodes::NodeReport& x = r.per_node[n];
    nodes.push_back({{"node", n},
                     {"pixels", x.work.items},
                     {"tiles", x.work.tiles},
                     {"rays", x.work.rays.rays()},
                     {"svm", json_svm(x.svm)},
                     {"pages_served", x.served.pages_served},
                     {"bytes_served", x.served.bytes_served},
                     {"served_in_place", x.served.served_in_place},
                     {"own_bytes", x.own_bytes},
                     {"cache_pages", x.cache_capacity},
                     {"evictions", x.evictions},
                     {"peak_resident_bytes", x.peak_resident_bytes}});
  }
  return nodes;
}

Json json_network(const nodes::NetworkStats& s) {
  Json by_kind = Json::object();
  for (const auto& [kind, h] : s.hops_by_kind)
    by_kind[kind_name(kind)] = {{"packets", h.packets}, {"mean_hops", h.mean()}, {"max_hops", h.max_hops}};
  Json busiest = nullptr;
  if (const nodes::LinkStats* b = nodes::busiest_link(s))
    busiest = {{"from", b->from}, {"to", b->to}, {"packets", b->packets}, {"bytes", b->bytes}};
  return {{"packets", s.hops.packets},
          {"mean_hops", s.hops.mean()},
          {"max_hops", s.hops.max_hops},
          {"by_kind", std::move(by_kind)},
          {"busiest_link", std::move(busiest)}};
}

// [{"id": 17, "kind": "page_request", "nodes": [5, 4, 6]}, ...]
Json json_routes(const nodes::NetworkStats& s) {
  Json routes = Json::array();
  for (const nodes::RouteRecord& r : s.routes)
    routes.push_back({{"id", r.id}, {"kind", kind_name(r.kind)}, {"nodes", r.route}});
  return routes;
}

// Which ranks ran which nodes, and what crossed between them.
}  // namespace

std::string rank_nodes(const nodes::RankReport& rank) {
  return std::to_string(rank.first_node) + "-" + std::to_string(rank.first_node + rank.node_count - 1);
}

namespace {

void print_ranks(std::ostream& out, const nodes::MachineReport& r) {
  if (r.ranks.empty()) return;
  const topology::Topology& t = r.topology;
  std::size_t links = 0;
  for (topology::NodeId n = 0; n < t.size(); ++n) links += t.degree(n);
  out << "ranks          " << r.ranks.size() << " processes, " << r.cut_links << " of " << links / 2
      << " links cut\n"
      << "  " << std::setw(4) << "rank" << std::setw(13) << "nodes" << std::setw(8) << "threads" << std::setw(13)
      << "packets out" << std::setw(13) << "bytes out" << std::setw(11) << "messages" << std::setw(13)
      << "scene bytes" << std::setw(9) << "cpu s" << std::setw(9) << "wall s" << "\n";
  for (const nodes::RankReport& k : r.ranks) {
    out << "  " << std::setw(4) << k.rank << std::setw(13) << rank_nodes(k) << std::setw(8) << k.threads
        << std::setw(13) << k.bridge.packets_sent << std::setw(13) << k.bridge.bytes_sent << std::setw(11)
        << k.bridge.messages_sent << std::setw(13) << k.peak_scene_bytes << std::setprecision(3) << std::setw(9)
        << k.cpu_seconds << std::setw(9) << k.wall_seconds << "\n";
  }
}

Json json_ranks(const nodes::MachineReport& r) {
  Json ranks = Json::array();
  for (const nodes::RankReport& k : r.ranks)
    ranks.push_back({{"rank", k.rank},
                     {"first_node", k.first_node},
                     {"nodes", k.node_count},
                     {"threads", k.threads},
                     {"packets_sent", k.bridge.packets_sent},
                     {"bytes_sent", k.bridge.bytes_sent},
                     {"packets_received", k.bridge.packets_received},
                     {"bytes_received", k.bridge.bytes_received},
                     {"messages_sent", k.bridge.messages_sent},
                     {"wire_bytes_sent", k.bridge.wire_bytes_sent},
                     {"post_seconds", static_cast<double>(k.bridge.post_nanoseconds) * 1e-9},
                     {"polls", k.bridge.polls},
                     {"peak_scene_bytes", k.peak_scene_bytes},
                     {"cpu_seconds", k.cpu_seconds},
                     {"wall_seconds", k.wall_seconds}});
  return ranks;
}

// The relays' counters per thread, as print_relays sums them.
Json json_relays(const nodes::MachineReport& r) {
  Json relays = Json::array();
  for (const nodes::RelayCounters& t : r.relays)
    relays.push_back({{"packets_sent", t.packets_sent},
                      {"packets_received", t.packets_received},
                      {"sent_in_place", t.sent_in_place},
                      {"wakes", t.wakes},
                      {"signals", t.signals}});
  return relays;
}

Json json_host_threads(const std::vector<csp::ThreadUse>& threads) {
  Json out = Json::array();
  for (const csp::ThreadUse& t : threads)
    out.push_back({{"seconds", t.seconds},
                   {"idle_seconds", t.idle_seconds},
                   {"running_seconds", t.running_seconds},
                   {"spinning_seconds", t.spinning_seconds},
                   {"sleeping_seconds", t.sleeping_seconds},
                   {"cpu_seconds", t.cpu_seconds},
                   {"waits", t.waits},
                   {"sleeps", t.sleeps},
                   {"remote_wakes", t.remote_wakes},
                   {"sleepers_woken", t.sleepers_woken}});
  return out;
}

// One line per runtime thread: where its time went, as shares of its wall
// time, and the CPU time the OS gave it (less than running + spinning when
// other threads had its core).
// One line per OS thread; in a run over ranks, named by rank and its
// thread there (the threads come rank by rank, in the order of `ranks`).
void print_thread_use(std::ostream& out, const std::vector<csp::ThreadUse>& threads,
                      const std::vector<nodes::RankReport>& ranks) {
  std::vector<std::string> labels;
  for (const nodes::RankReport& rank : ranks)
    for (unsigned t = 0; t < rank.threads; ++t)
      labels.push_back("rank " + std::to_string(rank.rank) + " thread " + std::to_string(t));
  if (labels.size() != threads.size()) labels.clear();
  for (std::size_t t = 0; t < threads.size(); ++t) {
    const csp::ThreadUse& u = threads[t];
    const double share = u.seconds > 0 ? 100 / u.seconds : 0;
    std::ostringstream label;
    if (labels.empty())
      label << "thread " << t;
    else
      label << labels[t];
    out << std::left << std::setw(static_cast<int>(std::max<std::size_t>(15, label.str().size() + 1))) << label.str()
        << std::right << std::setprecision(3) << u.seconds
        << " s: " << std::setprecision(1) << "running " << share * u.running_seconds << "%, spinning "
        << share * u.spinning_seconds << "%, sleeping " << share * u.sleeping_seconds << "%; cpu "
        << share * u.cpu_seconds << "%; " << u.sleeps << " sleeps in " << u.waits << " idle waits; woke "
        << u.remote_wakes << " processes of other threads; woke a sleeping thread " << u.sleepers_woken
        << " times\n";
  }
  out << std::setprecision(3);
}

// What crossed between threads through the relays: packets, of which the
// routers put in the rings themselves, and the wakes and signals they took
// (packets per wake is the batching).
void print_relays(std::ostream& out, const nodes::MachineReport& r) {
  if (r.relays.empty()) return;
  nodes::RelayCounters all;
  for (const auto& t : r.relays) all += t;
  out << "between threads " << all.packets_sent << " packets on " << r.relayed_links << " relayed links ("
      << all.sent_in_place << " put in by routers), in " << all.wakes << " relay wakes (" << std::setprecision(2)
      << (all.wakes ? static_cast<double>(all.packets_sent) / all.wakes : 0.0) << " per wake) and " << all.signals
      << " signals\n"
      << std::setprecision(3);
}

}  // namespace

std::string busy_cores_note(const std::vector<csp::ThreadUse>& threads, bool over_ranks, unsigned cpus) {
  if (threads.size() < 2) return "";
  double cpu = 0, wanted = 0;
  for (const csp::ThreadUse& u : threads) {
    cpu += u.cpu_seconds;
    wanted += u.running_seconds + u.spinning_seconds;
  }
  if (!(wanted > 0) || cpu >= 0.9 * wanted) return "";
  std::ostringstream out;
  out << std::fixed << std::setprecision(0) << "busy cores     the threads had a core " << 100 * cpu / wanted
      << "% of the time they ran or spun: ";
  if (over_ranks)
    out << "other programs, or ranks beyond the cores, took the cores, and fewer ranks or --threads";
  else if (cpus > 0 && threads.size() > cpus)
    out << threads.size() << " threads took turns on the " << cpus << " CPUs this process may use, and fewer --threads";
  else
    out << "other programs took the cores, and fewer --threads";
  out << " may be faster (a machine's threads wait on each other)\n";
  return out.str();
}

double MachineSummary::parallel_seconds() const {
  return report.model ? report.predicted_seconds : report.wall_seconds;
}

double MachineSummary::speedup() const {
  return serial && parallel_seconds() > 0 ? serial->seconds / parallel_seconds() : 0.0;
}

double MachineSummary::efficiency() const {
  return report.nodes > 0 ? speedup() / report.nodes : 0.0;
}

void print_machine_report(std::ostream& out, const MachineSummary& m) {
  const nodes::MachineReport& r = m.report;
  const nodes::SvmStats svm = r.svm();
  const nodes::ServerCounters served = r.served();
  out << std::fixed << std::setprecision(1);
  out << "machine        " << r.topology.spec() << ": " << count_of(r.nodes, "node") << ", "
      << count_of(r.workers_per_node, "pixel computer") << " each (prefetch " << r.prefetch << "), "
      << nodes::schedule_name(r.schedule) << " schedule";
  if (r.schedule != nodes::Schedule::static_split) out << " (grain " << r.grain;
  if (r.schedule == nodes::Schedule::affinity) out << ", " << r.farmer.steals << " steals";
  if (r.schedule != nodes::Schedule::static_split) out << ")";
  out << " in " << nodes::pixel_order_name(r.pixel_order) << " order, " << count_of(r.threads, "thread")
      << ", cache " << r.cache_pages << " pages (" << size_text(double(r.cache_pages) * r.page_size) << ") per node";
  if (const std::uint32_t used = largest_cache(r); used < r.cache_pages)
    out << ", holding every remote page (at most " << used << ")";
  out << "\n"
      << std::setprecision(4) << "svm            " << svm.accesses() << " page accesses: "
      << svm.own_hits << " local, " << svm.cache_hits << " cache hits, " << svm.misses << " misses (" << svm.coalesced
      << " coalesced), miss ratio " << svm.miss_ratio() << "\n"
      << "page traffic   " << served.pages_served << " page communications, "
      << served.bytes_served << " bytes; " << r.rays().pages_per_sample()
      << " distinct pages per " << (m.corner_samples ? "sample" : "pixel") << "\n";
  print_per_node(out, r, m.corner_samples ? "samples" : "pixels");
  out << nodes::format_summary(r.network, r.topology, kind_name);
  print_ranks(out, r);
  out << std::setprecision(3) << "wall time      " << r.wall_seconds << " s on ";
  if (r.ranks.empty())
    out << count_of(r.threads, "thread");
  else
    out << count_of(r.ranks.size(), "rank") << " of " << count_of(r.threads, "thread") << " each";
  if (!r.model)
    out << std::setprecision(1) << ", idle " << 100 * r.idle_share() << "% of thread time" << std::setprecision(3);
  else
    out << "; predicted " << r.predicted_seconds << " s (" << r.model->describe() << ")";
  out << "\n";
  if (!r.model) {
    print_thread_use(out, r.host_threads, r.ranks);
    out << busy_cores_note(r.host_threads, !r.ranks.empty(), usable_cpus());
  }
  print_relays(out, r);
  if (m.serial)
    out << "speedup        " << m.speedup() << " (1 node: " << m.serial->seconds << " s on "
        << count_of(m.serial->threads, "thread") << "; " << count_of(r.nodes, "node") << ": " << m.parallel_seconds()
        << " s on " << count_of(r.threads, "thread") << (r.model ? ", predicted" : "") << "), efficiency "
        << m.efficiency() << "\n";
}

void print_routes(std::ostream& out, const nodes::MachineReport& report) {
  const auto& routes = report.network.routes;
  if (routes.empty()) return;
  out << "routes         " << count_of(routes.size(), "packet") << " traced, hop by hop:\n";
  for (const nodes::RouteRecord& r : routes) out << "  " << nodes::format_route(r, kind_name) << "\n";
}

Json cost_model_json(const nodes::CostModel& model) {
  return {{"name", model.name},
          {"unit", model.unit},
          {"box", model.box},
          {"prim", model.prim},
          {"shade", model.shade},
          {"page", model.page},
          {"serve", model.serve},
          {"msg", model.msg},
          {"hop", model.hop},
          {"bandwidth", model.bandwidth},
          {"description", model.describe()}};
}

Json machine_json(const MachineSummary& m) {
  const nodes::MachineReport& r = m.report;
  const nodes::ServerCounters served = r.served();
  Json j = {{"topology", r.topology.spec()},
            {"nodes", r.nodes},
            {"threads", r.threads},
            {"workers_per_node", r.workers_per_node},
            {"prefetch", r.prefetch},
            {"schedule", std::string(nodes::schedule_name(r.schedule))},
            {"pixel_order", std::string(nodes::pixel_order_name(r.pixel_order))},
            {"grain", r.grain},
            {"steals", r.farmer.steals},
            {"cache_pages", r.cache_pages},
            {"cache_kb", double(r.cache_pages) * r.page_size / 1024.0},
            {"cache_pages_largest_in_use", largest_cache(r)},
            {"database_pages", r.page_count},
            {"database_kb", double(r.page_count) * r.page_size / 1024.0},
            {"svm", json_svm(r.svm())},
            {"page_communications", served.pages_served},
            {"page_bytes", served.bytes_served},
            {"page_communications_served_in_place", served.served_in_place},
            {"pages_per_pixel", r.rays().pages_per_sample()},
            {"imbalance", {{"pixels", r.item_imbalance()}, {"rays", r.ray_imbalance()}}},
            {"per_node", json_per_node(r)},
            {"network", json_network(r.network)},
            {"routes", json_routes(r.network)},
            {"cut_links", r.cut_links},
            {"ranks", json_ranks(r)},
            {"wall_seconds", r.wall_seconds}};
  if (!r.model) {
    j["host_threads"] = json_host_threads(r.host_threads);
    j["relayed_links"] = r.relayed_links;
    j["relays"] = json_relays(r);
  } else {
    j["cost_model"] = cost_model_json(*r.model);
    j["predicted_seconds"] = r.predicted_seconds;
  }
  j["serial"] = nullptr;
  if (m.serial)
    j["serial"] = {{"seconds", m.serial->seconds},
                   {"threads", m.serial->threads},
                   {"parallel_seconds", m.parallel_seconds()},
                   {"speedup", m.speedup()},
                   {"efficiency", m.efficiency()}};
  return j;
}

std::string tiles_csv(const nodes::MachineReport& report) {
  struct Row {
    std::size_t node;
    const nodes::TileSpan* span;
  };
  std::vector<Row> rows;
  for (std::size_t n = 0; n < report.per_node.size(); ++n)
    for (const nodes::TileSpan& span : report.per_node[n].work.spans) rows.push_back({n, &span});
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return std::tie(a.span->start, a.node, a.span->worker) < std::tie(b.span->start, b.node, b.span->worker);
  });
  std::ostringstream f;
  f << std::setprecision(9) << "node,worker,first_item,items,start_s,end_s,page_requests,rays\n";
  for (const Row& r : rows) {
    const nodes::TileSpan& s = *r.span;
    f << r.node << ',' << s.worker << ',' << s.tile.first << ',' << s.tile.count << ',' << s.start << ',' << s.end
      << ',' << s.page_requests << ',' << s.rays << '\n';
  }
  return f.str();
}

}  // namespace app
