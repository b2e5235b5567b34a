// The configured paths (see paths.hpp); defined by tests/CMakeLists.txt.
#include "tests/support/paths.hpp"

namespace test {

std::string vmpray_binary() { return VMPRAY_BINARY; }
std::string shared_scenes() { return VMPRAY_SHARED_SCENES; }

}  // namespace test
