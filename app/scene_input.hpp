// Turns the SCENE argument into a tracer::Scene: an existing file (or "-" for
// stdin) is parsed as NFF, any other name is looked up among the built-ins.
// Image-size and tessellation options are applied here, before any build.
#pragma once

#include "app/options.hpp"
#include "tracer/scene.hpp"

namespace app {

// Throws std::runtime_error with one line naming the file:line or the scene.
tracer::Scene load_scene(const Options& options);

}  // namespace app
