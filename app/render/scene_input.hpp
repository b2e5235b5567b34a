// Turns the SCENE argument into a tracer::Scene: anything existing that is not
// a directory (a regular file, a FIFO, /dev/stdin, a process substitution; or
// "-" for stdin) is parsed as NFF, any other name is looked up among the
// built-ins. A directory is refused as such unless a built-in has its name.
// Image-size and tessellation options are applied here, before any build.
#pragma once

#include <string>
#include <vector>

#include "app/render/options.hpp"
#include "tracer/scene.hpp"

namespace app {

// What makes a scene render as nothing: no objects (the background alone),
// or no lights (every surface black). One line each, naming the scene.
std::vector<std::string> scene_warnings(const tracer::Scene& scene);

// Prints scene_warnings on stderr ("vmpray: warning: ..."); the render goes on.
// Throws std::runtime_error with one line naming the file:line or the scene;
// UsageError (a bad argument) for a name that is neither a file nor a
// built-in, a built-in spec that is malformed, or a tessellation (--tessellate,
// or a spec's tRES) too large for the memory, refused before it is made.
tracer::Scene load_scene(const Options& options);

}  // namespace app
