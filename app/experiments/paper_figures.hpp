// The paper's own figures (Badouel & Priol 1990), for putting beside ours:
// Table 2's synthesis times on the iPSC/2 hypercube at 512x512 pixels.
// Invariants: a figure is returned only where the paper printed one, for the
// built-in scene that stands for the paper's (teapot, mountain, rings4,
// tetra9, tetra10) at 512x512; anything else gets none, never a guess.
// Figure 8 is printed as curves only, so no number of it is held here.
#pragma once

#include <optional>
#include <string_view>

namespace app {

// Table 2: seconds to synthesise `scene` at width x height on `nodes` processors.
std::optional<double> paper_synthesis_seconds(std::string_view scene, int width, int height, int nodes);

// ours / paper - 1: +0.05 is 5% slower than the paper.
inline double deviation_from(double ours, double paper) { return ours / paper - 1; }

}  // namespace app
