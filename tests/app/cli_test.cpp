// The vmpray executable end to end: exit codes, one-line errors, no partial
// output on failure, an image too large for the memory refused up front,
// image and JSON on success, scenes from FIFOs, and signals held back while
// the outputs are written, and how that phase ends.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "app/render/output_files.hpp"
#include "tests/support/scratch.hpp"

namespace {

namespace fs = std::filesystem;

using test::Outcome;

class Cli : public test::ScratchTest {
 protected:
  Cli() : ScratchTest("vmpray_cli_") {}
  Outcome run(const std::string& args) { return run_vmpray(args); }
  std::size_t lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }
};

TEST_F(Cli, MissingSceneFileIsARuntimeErrorWithNoOutput) {
  const Outcome r = run("no/such/scene.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("no/such/scene.nff"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, UnknownBuiltinIsABadArgument) {
  const Outcome r = run("nosuchscene -o out.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, BadOptionValueIsAUsageError) {
  for (const char* args : {"--page-size 1000 -o out.png", "--accel octree -o out.png",
                           "-o out.bmp", "--bogus -o out.png"}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
  EXPECT_FALSE(fs::exists(dir_ / "out.bmp"));
}

TEST_F(Cli, MalformedSceneNamesFileAndLine) {
  std::ofstream(dir_ / "bad.nff") << "v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\n"
                                     "hither 1\nresolution 8 8\ns 0 0 zero 1\n";
  const Outcome r = run("bad.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("bad.nff:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

const char* kTinyScene = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 0.1 resolution 8 8\nl 0 0 5\ns 0 0 0 1\n";

// Writes `text` into the FIFO as soon as a reader has opened it; gives up
// once `stop` is set, so a reader that never comes cannot hang the test.
std::thread feed_fifo(const fs::path& fifo, std::string text, const std::atomic<bool>& stop) {
  return std::thread([fifo, text, &stop] {
    while (!stop) {
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // fails until there is a reader
      if (fd >= 0) {
        EXPECT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
        ::close(fd);
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
}

TEST_F(Cli, ReadsTheSceneFromAFifo) {
  ASSERT_EQ(::mkfifo((dir_ / "scene.nff").c_str(), 0600), 0);
  std::atomic<bool> stop = false;
  std::thread writer = feed_fifo(dir_ / "scene.nff", kTinyScene, stop);
  const Outcome r = run("scene.nff --single -q -o out.ppm");
  stop = true;
  writer.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.ppm"));
}

TEST_F(Cli, DirectoryAsSceneSaysSo) {
  fs::create_directory(dir_ / "scenes");
  const Outcome r = run("scenes/ -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "vmpray: scenes/: is a directory, not an NFF file\n");
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Cli, BuiltinNameWinsOverADirectoryOfThatName) {
  fs::create_directory(dir_ / "tetra");
  const Outcome r = run("tetra --single -q --width 8 --height 8 -o out.ppm");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.ppm"));
}

TEST_F(Cli, RendersImageAndJsonStats) {
  const Outcome r = run("tetra:1 --width 24 --height 16 -o out.ppm --stats s.json --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_EQ(fs::file_size(dir_ / "out.ppm"), std::string("P6\n24 16\n255\n").size() + 24 * 16 * 3);
  std::ifstream in(dir_ / "s.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("\"primary\": 384"), std::string::npos) << ss.str();
  EXPECT_NE(ss.str().find("\"page_size\": 1024"), std::string::npos);
  EXPECT_NE(ss.str().find("\"shadow_rays\": \"facing\""), std::string::npos);
}

TEST_F(Cli, ReportNamesTheShadowRayPolicyInTextAndJson) {
  const Outcome r = run_vmpray("tetra:1 --single --width 16 --height 16 -o out.ppm --shadow-rays all --stats s.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(shadow rays to every light)"), std::string::npos) << r.out;
  EXPECT_NE(test::read_file(dir_ / "s.json").find("\"shadow_rays\": \"all\""), std::string::npos);
}

// A process that may map 2 GB (ulimit -v) is told at once that the largest
// image needs more, instead of failing to allocate it once the scene is
// built, and that a complete graph of 2048 nodes and its 4 million link
// queues need more, before minutes of setting them up; a small image on the
// default machine still renders under the same limit.
TEST_F(Cli, WhatIsTooLargeForTheMemoryIsRefusedBeforeTheRender) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 2 GB of address space";
#endif
  const auto limited = [&](const std::string& args) { return run_vmpray(args, "stdout.txt", "ulimit -v 2000000"); };
  const std::pair<const char*, const char*> too_large[] = {
      {"teapot --width 16384 --height 16384 -o out.png",
       "vmpray: --width/--height: a 16384x16384 image needs about 8.1 GB, more than the 2.0 GB this process may map "
       "(ulimit -v)\n"},
      {"teapot --topology complete --nodes 2048 --threads 1 --width 16 --height 16 -o out.png",
       "vmpray: --nodes/--topology: complete:2048 (2048 nodes, 4192256 link queues) needs about 5.1 GB of address "
       "space with its image, more than the 2.0 GB this process may map (ulimit -v)\n"},
  };
  for (const auto& [args, message] : too_large) {
    const Outcome refused = limited(args);
    EXPECT_EQ(refused.exit_code, 2) << args;
    EXPECT_EQ(refused.err, message);
    EXPECT_EQ(refused.out, "") << args;
    EXPECT_FALSE(fs::exists(dir_ / "out.png")) << args;
  }
  const Outcome rendered = limited("teapot --width 64 --height 64 -q -o out.png");
  EXPECT_EQ(rendered.exit_code, 0) << rendered.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.png"));
}

// A machine whose process stacks do not fit in the address space this
// process may map is refused before it is built: every process's stack is
// mapped whole (1024 nodes run about 4100 processes with 256 KB stacks: over
// 1 GB), however little of it is resident.
TEST_F(Cli, AMachineTooLargeForTheAddressSpaceIsRefusedBeforeItIsBuilt) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 600 MB of address space";
#endif
  const Outcome r = run_vmpray("teapot --nodes 1024 --threads 2 --width 16 --height 16 -q -o out.png", "stdout.txt",
                               "ulimit -v 600000");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "vmpray: --nodes/--topology: hypercube:10 (1024 nodes, 10240 link queues, 1024 of them between 2 threads) "
            "needs about 1.0 GB of address space with its image, more than the 614 MB this process may map "
            "(ulimit -v)\n");
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

// Wherever the memory runs out (ulimit -v from where the runtime threads
// barely start to where the render fits), a run, in real or virtual time,
// either succeeds or ends with one line that points at the limit: status 2
// when the check before the run refuses it, 1 when an allocation fails
// (however many processes failed at once): never an abort from
// an allocation that fails inside Boost.Fiber's noexcept scheduling calls,
// nor a hang from a deadlock that finds no memory to describe itself.
TEST_F(Cli, RunningOutOfAddressSpaceAnywhereEndsInSuccessOrOneLine) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit in 200 MB of address space";
#endif
  int failures = 0;
  for (const char* timing : {"", " --timing virtual"}) {
    for (int limit_mb = 50; limit_mb <= 200; limit_mb += 10) {
      const std::string limit = "ulimit -v " + std::to_string(limit_mb * 1000);
      const std::string cmd = "cd '" + dir_.string() + "' && " + limit + " && exec timeout -s KILL 60 " +
                              test::vmpray_binary() + " teapot --threads 8 --width 64 --height 64 -q -o out.png" + timing +
                              " >stdout.txt 2>stderr.txt </dev/null";
      const int status = std::system(cmd.c_str());
      const std::string err = test::read_file(dir_ / "stderr.txt");
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      SCOPED_TRACE(limit + timing + ": status " + std::to_string(code) + ", stderr: " + err);
      ASSERT_TRUE(code == 0 || code == 1 || code == 2);
      if (code == 0) {
        EXPECT_EQ(err, "");
        EXPECT_TRUE(fs::exists(dir_ / "out.png"));
      } else {
        ++failures;
        EXPECT_EQ(lines(err), 1u);
        EXPECT_EQ(err.rfind("vmpray: ", 0), 0u);
        EXPECT_NE(err.find("ulimit -v"), std::string::npos);
        EXPECT_FALSE(fs::exists(dir_ / "out.png"));
      }
      fs::remove(dir_ / "out.png");
    }
  }
  EXPECT_GT(failures, 0) << "no limit was low enough to fail";
}

// A signal that would end the command while it writes its outputs waits
// until they are all in place (or all removed), then goes through.
TEST(OutputPhase, HoldsAnInterruptUntilItEnds) {
  static volatile std::sig_atomic_t delivered = 0;
  const auto before = std::signal(SIGINT, [](int) { delivered = 1; });
  {
    const app::OutputPhase phase;
    EXPECT_FALSE(phase.interrupted());
    std::raise(SIGINT);
    EXPECT_EQ(delivered, 0);
    EXPECT_TRUE(phase.interrupted());
  }
  EXPECT_EQ(delivered, 1);
  std::signal(SIGINT, before);
}

class OutputPhaseFiles : public test::ScratchTest {
 protected:
  OutputPhaseFiles() : ScratchTest("vmpray_output_phase_") {}
  // A file written and added to `phase`, as a command's output.
  fs::path output(app::OutputPhase& phase, const std::string& name) {
    return phase.files().write_text(dir_ / name, "output\n");
  }
};

TEST_F(OutputPhaseFiles, FinishKeepsTheFiles) {
  fs::path path;
  {
    app::OutputPhase phase;
    path = output(phase, "kept.txt");
    std::ostringstream out;
    EXPECT_EQ(phase.finish(out, "report"), 0);
  }
  EXPECT_TRUE(fs::exists(path));
}

// The files go first, then the held signal: whatever the signal does next,
// nothing of the command is left.
TEST_F(OutputPhaseFiles, AfterASignalFinishRemovesTheFilesThenLetsItThrough) {
  static const char* watched = nullptr;
  static volatile std::sig_atomic_t delivered = 0, file_there_at_delivery = 0;
  const auto before = std::signal(SIGINT, [](int) {
    delivered = 1;
    file_there_at_delivery = ::access(watched, F_OK) == 0;
  });
  fs::path path;
  {
    app::OutputPhase phase;
    path = output(phase, "removed.txt");
    watched = path.c_str();
    std::raise(SIGINT);
    std::ostringstream out;
    EXPECT_EQ(phase.finish(out, "report"), 1);
    EXPECT_TRUE(fs::exists(path));  // until the phase ends
    EXPECT_EQ(delivered, 0);
  }
  EXPECT_EQ(delivered, 1);
  EXPECT_EQ(file_there_at_delivery, 0);
  EXPECT_FALSE(fs::exists(path));
  std::signal(SIGINT, before);
}

TEST_F(OutputPhaseFiles, AnUnwritableStandardOutputFailsAndRemovesTheFiles) {
  fs::path path;
  {
    app::OutputPhase phase;
    path = output(phase, "removed.txt");
    std::ostream out(nullptr);  // bad from the start, as a stream whose writes failed
    try {
      phase.finish(out, "table");
      ADD_FAILURE() << "finish() accepted a standard output that cannot be written";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "standard output: cannot write the table");
    }
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
