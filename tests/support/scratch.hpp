// Test support shared by the suites that run the vmpray binary or write
// files: a scratch directory per test, whole-file reads, and running the
// binary in that directory with its output captured.
//
// Invariants: every test gets a fresh, empty directory named after the suite
// prefix, the test and the process (so two builds' suites can run at once),
// removed again when the test ends; run_vmpray() never
// reads standard input and reports stderr without ASan's expected fiber-stack
// warning (sanitizer_noise below), so assertions about one-line errors hold
// under the sanitizer build too.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/paths.hpp"

namespace test {

namespace fs = std::filesystem;

// Removes AddressSanitizer's expected fiber-stack warning from a captured
// stderr. Debian's Boost.Context does not announce stack switches to ASan,
// so a C++ exception thrown on a fiber stack makes ASan print a warning
// ("ASan is ignoring requested __asan_handle_no_return ...") followed by two
// lines of explanation. That is not output of vmpray; everything else is kept.
inline std::string without_sanitizer_noise(const std::string& captured) {
  std::istringstream in(captured);
  std::string kept, line;
  while (std::getline(in, line)) {
    const bool noise = (line.rfind("==", 0) == 0 && line.find("WARNING: ASan") != std::string::npos) ||
                       line == "False positive error reports may follow" ||
                       line.rfind("For details see https://github.com/google/sanitizers/issues/189", 0) == 0;
    if (!noise) kept += line + "\n";
  }
  return kept;
}

inline std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Outcome {
  int exit_code;
  std::string out, err;
};

// A fixture whose tests each own the directory dir_.
class ScratchTest : public ::testing::Test {
 protected:
  explicit ScratchTest(const std::string& prefix)
      : dir_(fs::temp_directory_path() / (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                          "-" + std::to_string(::getpid()))) {}
  void SetUp() override {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `vmpray args` in dir_; stdout and stderr are captured in files there
  // (stdout goes to `stdout_to` instead when given: a shell redirection target).
  // `setup`, if given, is a shell command run first in the same shell, such
  // as a ulimit for the binary.
  Outcome run_vmpray(const std::string& args, const std::string& stdout_to = "stdout.txt",
                     const std::string& setup = "") const {
    const std::string cmd = "cd '" + dir_.string() + "' && " + (setup.empty() ? "" : setup + " && ") +
                            test::vmpray_binary() + " " + args + " >" + stdout_to + " 2>stderr.txt </dev/null";
    const int status = std::system(cmd.c_str());
    return {WEXITSTATUS(status), read_file(dir_ / "stdout.txt"),
            without_sanitizer_noise(read_file(dir_ / "stderr.txt"))};
  }

  fs::path dir_;
};

}  // namespace test
