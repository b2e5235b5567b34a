// Turns the SCENE argument into a tracer::Scene: anything existing that is not
// a directory (a regular file, a FIFO, /dev/stdin, a process substitution; or
// "-" for stdin) is parsed as NFF, any other name is looked up among the
// built-ins. A directory is refused as such unless a built-in has its name.
// Image-size and tessellation options are applied here, before any build.
#pragma once

#include "app/options.hpp"
#include "tracer/scene.hpp"

namespace app {

// Throws std::runtime_error with one line naming the file:line or the scene;
// UsageError (a bad argument) for a name that is neither a file nor a
// built-in, or a built-in spec that is malformed.
tracer::Scene load_scene(const Options& options);

}  // namespace app
