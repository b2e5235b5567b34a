// Data files from tracer/data/, compiled into the library (see CMakeLists.txt).
#pragma once

#include <string_view>

namespace tracer::embedded {

// tracer/data/utah-teapot.txt: the 32 Bezier patches of the Utah teapot.
extern const std::string_view utah_teapot;

}  // namespace tracer::embedded
