// Where the tests find the vmpray binary and the SPD scenes: paths fixed when
// the build is configured, compiled into paths.cpp alone, so that no other
// test file's compile command names the checkout's folder and a compiler
// cache serves every other test object to any clone of the project.
#pragma once

#include <string>

namespace test {

std::string vmpray_binary();  // the vmpray executable of this build
std::string shared_scenes();  // the folder of SPD scene files (VMPRAY_SCENES_DIR)

}  // namespace test
