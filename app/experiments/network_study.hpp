// `vmpray network`: latency against offered load, per topology and traffic
// pattern, in virtual time (nodes/net/load_study.hpp runs each point).
//
// Each curve is a run per load, the load given as a fraction of the
// topology's channel-load bound for the pattern (1: the busiest link, the
// delivery channels counted, is offered its capacity). Writes DIR/network.csv,
// DIR/network.json (schema version, command line, each topology's cost
// table and every point), DIR/network.svg with one PNG a panel, a picture
// of each topology's link traffic at one load (DIR/network-links-K.svg),
// and DIR/network.html; prints the table. Points run side by side on --jobs
// threads; every file is the same whatever --jobs, but for the wall time.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/render/options.hpp"
#include "nodes/machine/timing.hpp"
#include "nodes/net/load_study.hpp"
#include "topology/topology.hpp"
#include "tracer/scene.hpp"

namespace app {

struct NetworkStudyOptions {
  std::vector<topology::Topology> topologies{topology::Topology::hypercube(6), topology::Topology::torus(8, 8),
                                             topology::Topology::mesh(8, 8), topology::Topology::ring(64),
                                             topology::Topology::complete(64)};  // parsed once, from --topology
  std::vector<nodes::TrafficPattern> patterns{nodes::TrafficPattern::uniform};
  std::vector<double> loads{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2};
  nodes::CostModel model = nodes::ipsc2_profile();  // its hop and bandwidth make the link model
  nodes::LoadStudyOptions study;                    // payload, buffers, hotspot share, seed
  std::string scene = "rings4";  // the render pattern's scene: a built-in or an NFF file
  int scene_size = 64;           // its image, pixels a side
  std::shared_ptr<const tracer::Scene> render_scene;  // scene, read when render is among the patterns
  double links_at = 0.5;  // the load whose link traffic each topology's picture shows (the nearest run)
  std::filesystem::path out_dir = "network";
  unsigned jobs = 1;
  bool quiet = false;
};

// Of the network JSON: raised whenever a field changes meaning or goes away.
inline constexpr int network_schema_version = 1;

// What a topology costs, to compare them at equal cost.
struct TopologyCost {
  std::string spec;
  std::size_t nodes = 0, links = 0;  // links: bidirectional, each counted once
  unsigned degree = 0, diameter = 0;
  double average_distance = 0;
  std::size_t bisection = 0;  // links cut by the best balanced bisection (closed form per kind)
};
TopologyCost topology_cost(const topology::Topology& t);

struct NetworkPoint {
  std::string topology;  // canonical spec, one of the options' topologies (study_topology)
  nodes::TrafficPattern pattern = nodes::TrafficPattern::uniform;
  double load = 0;            // fraction of the bound
  double bound = 0;           // packets per node per second at load 1
  double zero_load = 0;       // seconds: the pattern's mean distance at zero load
  std::shared_ptr<const nodes::RecordedTraffic> recorded;  // the render pattern's packets on this topology
  bool saturated = false;     // accepted under 95% of offered, or mean latency over 10x zero-load
  nodes::LoadResult result;
  double wall_seconds = 0;
};

struct NetworkTable {
  NetworkStudyOptions options;
  std::vector<TopologyCost> costs;
  std::vector<NetworkPoint> points;  // by topology, then pattern, then load
  std::vector<std::string> command_line;
};

// argv[0] is "network". Throws UsageError for a bad command line, naming
// the option; "help" for --help.
NetworkStudyOptions parse_network_options(int argc, const char* const argv[]);
std::string network_usage();
OptionGroup network_option_group();
std::string network_summary();

// The topology of options.topologies that `spec` (canonical) names;
// std::logic_error if none does.
const topology::Topology& study_topology(const NetworkStudyOptions& options, const std::string& spec);

NetworkTable run_network_study(const NetworkStudyOptions& options, std::ostream* progress);
// The packets of a render of options.scene on `t`, in virtual time under
// options.model, by source in the order each node sent them (a node's
// messages to itself, which cross no link, left out).
nodes::RecordedTraffic record_render_traffic(const NetworkStudyOptions& options, const topology::Topology& t);
std::string network_csv(const NetworkTable& table);
std::string network_json(const NetworkTable& table);

// The whole subcommand: exit status 0, 1 (run error) or 2 (usage).
int network_main(int argc, const char* const argv[]);

}  // namespace app
