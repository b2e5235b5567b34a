// What `vmpray --version` prints: the version, then how this binary was
// built (compiler, build type, sanitizers), so a report or a bug can be
// matched to the build that made it.
// Invariant: the first line is "vmpray VERSION", the project's version, as
// the reports and pages name it (VMPRAY_VERSION); every line ends in '\n'.
#pragma once

#include <string>

namespace app {

std::string version_text();

}  // namespace app
