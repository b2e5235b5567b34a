// The --version text (see version.hpp). The build type and the sanitizers
// come from the build (app/CMakeLists.txt defines them for this file only);
// the compiler names itself.
#include "app/render/version.hpp"

#ifndef VMPRAY_BUILD_TYPE
#define VMPRAY_BUILD_TYPE ""
#endif
#ifndef VMPRAY_SANITIZE
#define VMPRAY_SANITIZE ""
#endif

namespace app {

namespace {

// "GCC 12.2.0", "clang 14.0.6".
std::string compiler() {
#if defined(__clang__)
  std::string name = "clang " __clang_version__;
#elif defined(__GNUC__)
  std::string name = "GCC " __VERSION__;
#else
  std::string name = "an unknown compiler";
#endif
  while (!name.empty() && name.back() == ' ') name.pop_back();
  return name;
}

}  // namespace

std::string version_text() {
  const std::string build_type = VMPRAY_BUILD_TYPE, sanitizers = VMPRAY_SANITIZE;
  std::string text = "vmpray " VMPRAY_VERSION "\n";
  text += "compiler: " + compiler() + "\n";
  text += "build type: " + (build_type.empty() ? std::string("none") : build_type) + "\n";
  if (!sanitizers.empty()) text += "sanitizers: " + sanitizers + "\n";
  return text;
}

}  // namespace app
