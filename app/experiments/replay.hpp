// The replay page (--replay): one self-contained HTML page that plays a
// recorded machine run back (nodes/recorder.hpp): the machine as the
// machine picture draws it, each node coloured by what it does, packets
// moving hop by hop coloured by kind, the links' load building up, the image
// filling in tile by tile (or by owner), play, pause, speed, a time slider
// and stepping from event to event, counters, and details of a clicked node
// or packet.
// Invariants: the page refers to nothing outside it (its script and style
// inline, pictures as data: URLs); its data is one JSON document of arrays
// of numbers in <script type="application/json" id="replay-data">, times in
// integer ticks of data.tick seconds, each packet's times delta-coded from
// its injection; data.totals are the run's own figures (the --stats
// packets, hops, misses and pixels), which the page's counters reach at the
// end: packets recorded plus packets only counted.
// Pure functions of a finished run; the run must have been recorded.
#pragma once

#include <string>
#include <vector>

#include "app/render/machine_summary.hpp"
#include "nodes/machine/machine.hpp"
#include "tracer/image.hpp"

namespace app {

struct ReplaySource {
  std::string title;                             // the scene
  std::string made_by;                           // "vmpray 1.2.3"; empty: not shown
  std::vector<std::string> command_line;         // as typed; empty: not shown
  const nodes::MachineReport* report = nullptr;  // with a recording
  const tracer::Image* image = nullptr;          // the rendered frame
};

// The page's data, as embedded (std::invalid_argument if the run was not recorded).
Json replay_data(const ReplaySource& source);

// The whole page.
std::string replay_page(const ReplaySource& source);

// The page's script and style: app/experiments/replay.js and replay.css, compiled
// in at build time (cmake/embed_text.cmake), less their opening comments.
extern const char* const replay_script;
extern const char* const replay_style;

}  // namespace app
