// The up-front memory check: the estimate against peak resident sizes
// measured on real renders, and the refusal with its one-line message,
// under limits given here, so no test needs (or allocates) a large image.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "app/render/cpu_count.hpp"
#include "app/render/memory_check.hpp"
#include "tests/support/command_line.hpp"
#include "tests/support/scratch.hpp"

namespace {

using test::parse_words;

// Peak resident sizes of `vmpray teapot --width N --height N -q OPTIONS`
// (/usr/bin/time -f %M, 2 threads), less that of the same command at 64x64:
// what the image's buffers took. The estimate is to be within 5% of it, or
// 10% where tile records weigh: what the reallocations of their vectors and
// of the CSV's text leave resident varies from run to run (after the run,
// 2.0 to 2.2 times the records; the text, 2.25 to 2.5 times its length).
struct Measured {
  int size;
  const char* options;
  std::uint64_t kb, kb_at_64;
  double tolerance = 0.05;
};

const Measured measured[] = {
    {1024, "", 42068, 10320},
    {2048, "", 137324, 10280},
    {4096, "", 506324, 10380},
    {8192, "", 1993064, 10384},
    {16384, "", 7943392, 10328},
    {1024, "--single", 23412, 8588},
    {2048, "--single", 69524, 8532},
    {4096, "--single", 253816, 8488},
    {8192, "--single", 991300, 8520},
    {16384, "--single", 3940268, 8568},
    {4096, "--pixel-order scanline", 440428, 10408},
    {4096, "--spd-procedure", 506616, 10624},
    {4096, "--schedule static --nodes 1", 698100, 8492},
    {4096, "--schedule static --nodes 2", 600088, 8888},
    {4096, "--ownership o.png", 506020, 10380},
    {4096, "--report r.html", 508464, 12616},
    {4096, "--compare-serial --schedule static", 698408, 10312},
    {4096, "--timing virtual", 529656, 11804},
    {4096, "--schedule dynamic --grain 1024 --nodes 1", 501304, 8652},
    {2048, "--schedule dynamic --grain 1 --tiles t.csv", 714868, 11088, 0.10},
    {2048, "--schedule dynamic --grain 4 --tiles t.csv", 256828, 10776, 0.10},
    {2048, "--schedule dynamic --grain 1 --timeline t.svg --report r.html", 541808, 14128, 0.10},
};

TEST(MemoryEstimate, MatchesTheMeasuredPeaks) {
  for (const Measured& m : measured) {
    const double bytes = 1024.0 * static_cast<double>(m.kb - m.kb_at_64);
    const double estimate = static_cast<double>(app::image_memory_bytes(parse_words(m.options), m.size, m.size));
    EXPECT_LT(std::abs(estimate - bytes), m.tolerance * bytes)
        << m.size << "x" << m.size << " " << m.options << ": estimated " << estimate << ", measured " << bytes;
  }
}

TEST(MemoryEstimate, CountsCornerSamplesAndTheNodes) {
  const std::uint64_t pixels = 1000 * 1000, corners = 1001 * 1001;
  // Scanline order keeps no pixel order; the corner samples each take their colour, bit and owner.
  EXPECT_EQ(image_memory_bytes(parse_words("--pixel-order scanline --spd-procedure"), 1000, 1000) -
                image_memory_bytes(parse_words("--pixel-order scanline"), 1000, 1000),
            (corners - pixels) * 14 + corners / 8 - pixels / 8);
  // Static shares: every processor's share at once, and one of them on its way as a result.
  EXPECT_GT(image_memory_bytes(parse_words("--schedule static --nodes 1"), 1000, 1000),
            image_memory_bytes(parse_words("--schedule static --nodes 4"), 1000, 1000));
  // --single: its image, and as it is written the 8-bit copy.
  EXPECT_EQ(image_memory_bytes(parse_words("--single"), 1000, 1000), 15 * pixels);
}

// The machine's sizes are measured, not here but by scripts/memory-matrix.py
// (its quick rows in CI), which holds the estimate to peak resident sizes
// of real runs; these tests hold what the estimate counts.
TEST(MemoryEstimate, CountsTheLinksBetweenThreads) {
  // complete:4 on 2 threads: nodes 0 and 1 on one, 2 and 3 on the other; each of the 4 pairs across, both ways.
  const app::MachineMemory two = app::machine_memory(parse_words("--topology complete:4 --threads 2"), 661);
  EXPECT_EQ(two.link_queues, 12u);
  EXPECT_EQ(two.threads, 2u);
  EXPECT_EQ(two.relayed_link_queues, 8u);
  // A ring of 8 on 4 threads: the links between blocks of 2, both ways (a ring has two buffer classes).
  EXPECT_EQ(app::machine_memory(parse_words("--topology ring:8 --threads 4"), 661).relayed_link_queues, 4u * 2 * 2);
  const app::MachineMemory one = app::machine_memory(parse_words("--topology complete:4 --threads 1"), 661);
  EXPECT_EQ(one.relayed_link_queues, 0u);
  EXPECT_EQ(one.relay_bytes, 0u);
  EXPECT_GT(two.relay_bytes, 0u);
  EXPECT_EQ(two.total() - one.total(), two.relay_bytes);
  // No more threads than nodes; virtual time runs on one.
  EXPECT_EQ(app::machine_memory(parse_words("--topology complete:4 --threads 64"), 661).threads, 4u);
  EXPECT_EQ(app::machine_memory(parse_words("--topology complete:4 --threads 2 --timing virtual"), 661)
                .relayed_link_queues, 0u);
  // --threads 0 counts the threads the run will take (nodes::thread_count),
  // with the CPUs this process may use: two nodes take two when there are
  // two, and their links cross; one node takes one.
  const app::MachineMemory pair = app::machine_memory(parse_words("--topology complete:2"), 661);
  EXPECT_EQ(pair.threads, std::min(2u, app::usable_cpus()));
  EXPECT_EQ(pair.relayed_link_queues, pair.threads == 2 ? 2u : 0u);
  EXPECT_EQ(app::machine_memory(parse_words("--topology complete:1"), 661).threads, 1u);
}

TEST(MemoryEstimate, CountsTheReplaysRecordingAtItsBound) {
  const auto bytes = [](const char* options) { return app::machine_memory(parse_words(options), 661).recording_bytes; };
  EXPECT_EQ(bytes("--threads 1"), 0u);
  const std::uint64_t small = bytes("--threads 1 --replay r.html --replay-packets 1000");
  EXPECT_GT(small, 0u);
  EXPECT_EQ(bytes("--threads 1 --replay r.html --replay-packets 100000"), 100 * small);
}

TEST(MemoryCheck, RefusesAMachineAboveTheLimitNamingTheOptions) {
  const app::Options o = parse_words("--topology complete --nodes 4096 --threads 1");
  try {
    app::check_machine_memory(o, 16, 16, 661, {8'000'000'000});
    ADD_FAILURE() << "a complete graph of 4096 nodes passed an 8 GB limit";
  } catch (const app::UsageError& e) {
    EXPECT_STREQ(e.what(),
                 "--nodes/--topology: complete:4096 (4096 nodes, 16773120 link queues) needs about 10.9 GB with its "
                 "image, more than this machine's 8.0 GB");
  }
  // The image counts too. Worked out from the sizes memory_check.cpp gives: 4096 nodes of 38 KiB (router, page
  // server, page mailbox) with a pixel computer of 7.5 KiB, a page table and the pixel computer's page stamps of
  // 4 bytes a page each; 4095 link queues of 640 bytes at each node; and the 512x512 image at 30 1/8 bytes a
  // pixel (see the image's test below), where the 4096 pixel computers' tiles of 64 pixels, with one more
  // result on its way, hold 64 colours of 12 bytes more than the image's.
  constexpr std::uint64_t machine = 4096 * (38 * 1024 + 7680 + 2 * 4 * 661) + 4096ull * 4095 * 640;
  constexpr std::uint64_t needed = machine + 512 * 512 * 30 + 512 * 512 / 8 + 64 * 12;
  EXPECT_NO_THROW(app::check_machine_memory(o, 512, 512, 661, {needed}));
  EXPECT_THROW(app::check_machine_memory(o, 512, 512, 661, {needed - 1}), app::UsageError);
  EXPECT_NO_THROW(app::check_machine_memory(o, 16, 16, 661, {needed - 1}));
  // On two threads, half the links cross between them, each with its relays' state and ring entries.
  try {
    app::check_machine_memory(parse_words("--topology complete --nodes 4096 --threads 2"), 16, 16, 661,
                              {needed, app::MemoryLimit::Source::control_group});
    ADD_FAILURE() << "the relays of 8388608 links between threads took nothing";
  } catch (const app::UsageError& e) {
    EXPECT_STREQ(e.what(),
                 "--nodes/--topology: complete:4096 (4096 nodes, 16773120 link queues, 8388608 of them between 2 "
                 "threads) needs about 19.0 GB with its image, more than the 11.0 GB this process's control group may use");
  }
}

// Runs side by side: as many as fit together whichever run at once, so
// counted from the largest; a machine that does not fit alone is refused.
// Each run holds a machine, an image and its own copy of the database.
TEST(MemoryCheck, SideBySideRunsAreAsManyAsFitTogether) {
  constexpr std::uint32_t pages = 661;
  constexpr std::size_t page_size = 1024;
  constexpr std::uint64_t database_copy = pages * page_size;
  std::vector<nodes::MachineOptions> machines;
  std::vector<std::uint64_t> needs;
  for (const char* options : {"--nodes 1 --threads 1", "--nodes 4096 --threads 1", "--nodes 1024 --threads 1",
                              "--topology ring --nodes 4096 --threads 1"}) {
    const app::Options o = parse_words(options);
    machines.push_back(o.machine);
    needs.push_back(database_copy + app::machine_memory_bytes(o, pages) + app::image_memory_bytes(o, 64, 64));
  }
  const std::uint64_t hypercube = needs[1], ring = needs[3], all = needs[0] + needs[1] + needs[2] + needs[3];
  ASSERT_GT(hypercube, ring);
  ASSERT_GT(ring, needs[2]);
  const auto fit = [&](unsigned jobs, std::uint64_t limit) {
    return app::jobs_that_fit(machines, 64, 64, pages, page_size, jobs, {limit});
  };
  EXPECT_EQ(fit(4, all), 4u);
  EXPECT_EQ(fit(3, all), 3u);
  EXPECT_EQ(fit(4, all - 1), 3u);
  EXPECT_EQ(fit(4, all - database_copy), 3u);  // the machines fit, not with four copies of the database
  EXPECT_EQ(fit(4, hypercube + ring), 2u);
  EXPECT_EQ(fit(4, hypercube), 1u);
  try {
    fit(4, hypercube - 1);
    ADD_FAILURE() << "a machine larger than the limit passed";
  } catch (const app::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--nodes/--topology: hypercube:12 (4096 nodes, 49152 link queues)"),
              std::string::npos)
        << e.what();
  }
}

TEST(MemoryCheck, RefusesAnImageAboveTheLimitNamingTheOptions) {
  const app::Options o = parse_words("");
  try {
    app::check_image_memory(o, 16384, 16384, {4'000'000'000});
    ADD_FAILURE() << "a 16384x16384 image passed a 4 GB limit";
  } catch (const app::UsageError& e) {
    EXPECT_STREQ(e.what(), "--width/--height: a 16384x16384 image needs about 8.1 GB, more than this machine's 4.0 GB");
  }
  // Worked out from the sizes memory_check.cpp gives: on the default 16 nodes, a pixel's colour (12 bytes),
  // owner (2), arrival bit and place in the Hilbert order (4) while the image (12) is assembled, 30 1/8 bytes
  // a pixel; more than the pixel computers' tiles (16 of 48000 pixels, and one on its way) and more than the
  // outputs take (the image, its owners and the 8-bit copy: 17).
  constexpr std::uint64_t pixels = 4096 * 3000;
  constexpr std::uint64_t needed = pixels * 30 + pixels / 8;
  EXPECT_NO_THROW(app::check_image_memory(o, 4096, 3000, {needed}));
  EXPECT_THROW(app::check_image_memory(o, 4096, 3000, {needed - 1}), app::UsageError);
  using Source = app::MemoryLimit::Source;
  for (const auto& [source, whose] : {std::pair{Source::address_space, "this process may map (ulimit -v)"},
                                      std::pair{Source::control_group, "this process's control group may use"}}) {
    try {
      app::check_image_memory(parse_words("--single"), 4096, 4096, {200'000'000, source});
      ADD_FAILURE() << "a 4096x4096 image passed a 200 MB limit";
    } catch (const app::UsageError& e) {
      EXPECT_EQ(e.what(), std::string("--width/--height: a 4096x4096 image needs about 252 MB, more than the 200 MB ") +
                              whose);
    }
  }
}

// A control group tree in a scratch directory, as the kernel mounts it.
class ControlGroups : public test::ScratchTest {
 protected:
  ControlGroups() : ScratchTest("vmpray_cgroup_") {}
  void limit(const std::string& file, const std::string& value) {
    std::filesystem::create_directories((root_ / file).parent_path());
    std::ofstream(root_ / file) << value << "\n";
  }
  const std::filesystem::path& root_ = dir_;
};

// v2: the least memory.max from the process's group up to the root; "max"
// sets none.
TEST_F(ControlGroups, V2TakesTheLeastLimitOnThePathUpToTheRoot) {
  const std::string membership = "0::/user.slice/app.scope\n";
  EXPECT_EQ(app::cgroup_memory_limit(root_, membership), std::nullopt) << "no limit files at all";
  limit("user.slice/app.scope/memory.max", "max");
  EXPECT_EQ(app::cgroup_memory_limit(root_, membership), std::nullopt) << "max is no limit";
  limit("user.slice/memory.max", "8589934592");
  EXPECT_EQ(app::cgroup_memory_limit(root_, membership), 8589934592u) << "a parent's limit binds its children";
  limit("user.slice/app.scope/memory.max", "2147483648");
  EXPECT_EQ(app::cgroup_memory_limit(root_, membership), 2147483648u);
  limit("memory.max", "1073741824");
  EXPECT_EQ(app::cgroup_memory_limit(root_, membership), 1073741824u) << "up to the root";
  EXPECT_EQ(app::cgroup_memory_limit(root_, "0::/other.slice\n"), 1073741824u) << "another group: the root only";
}

// v1: the memory controller's hierarchy, whatever other controllers share it;
// the other hierarchies are not read.
TEST_F(ControlGroups, V1ReadsTheMemoryHierarchy) {
  limit("memory/docker/abc/memory.limit_in_bytes", "536870912");
  limit("memory/memory.limit_in_bytes", "9223372036854771712");
  limit("cpu/docker/abc/memory.limit_in_bytes", "1");
  EXPECT_EQ(app::cgroup_memory_limit(root_, "5:cpu,cpuacct:/docker/abc\n4:memory:/docker/abc\n0::/\n"),
            536870912u);
  EXPECT_EQ(app::cgroup_memory_limit(root_, "4:blkio,memory:/docker/abc\n"), 536870912u);
  EXPECT_EQ(app::cgroup_memory_limit(root_, "4:memoryx:/docker/abc\n"), std::nullopt) << "not the memory controller";
  EXPECT_EQ(app::cgroup_memory_limit(root_, "garbage\n"), std::nullopt);
}

TEST(MemoryCheck, TheLimitIsTheLeastOfPhysicalMemoryControlGroupAndAddressSpace) {
  using Source = app::MemoryLimit::Source;
  app::MemoryLimit expected{static_cast<std::uint64_t>(sysconf(_SC_PHYS_PAGES)) * sysconf(_SC_PAGE_SIZE),
                            Source::machine};
  const auto group = app::cgroup_memory_limit("/sys/fs/cgroup", test::read_file("/proc/self/cgroup"));
  if (group && *group < expected.bytes) expected = {*group, Source::control_group};
  rlimit space{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &space), 0);
  if (space.rlim_cur != RLIM_INFINITY && space.rlim_cur < expected.bytes)
    expected = {static_cast<std::uint64_t>(space.rlim_cur), Source::address_space};
  const app::MemoryLimit limit = app::memory_limit();
  EXPECT_EQ(limit.bytes, expected.bytes);
  EXPECT_EQ(limit.source, expected.source);
}

// --estimate-memory's first line holds the limit against the figure the
// check compares: the resident bytes, or under ulimit -v the bytes mapped,
// which a machine's stacks make the larger.
TEST(MemoryCheck, TheEstimateSetsTheLimitBesideTheFigureItHolds) {
  using Source = app::MemoryLimit::Source;
  const app::Options o = parse_words("--topology complete:256 --threads 2");
  const auto first_line = [&](app::MemoryLimit limit) {
    const std::string text = app::describe_memory(o, 16, 16, 661, limit);
    return text.substr(0, text.find('\n'));
  };
  const std::regex resident_held(R"(needs about \S+ \S+ \(\d+ bytes\) resident, less than this machine's 1000\.0 GB, )"
                                 R"(and maps about \S+ \S+)");
  EXPECT_TRUE(std::regex_match(first_line({1'000'000'000'000, Source::machine}), resident_held))
      << first_line({1'000'000'000'000, Source::machine});
  const std::regex mapped_held(R"(needs about \S+ MB \(\d+ bytes\) resident, and maps about \S+ MB, more than )"
                               R"(the 1 MB this process may map \(ulimit -v\))");
  EXPECT_TRUE(std::regex_match(first_line({1'000'000, Source::address_space}), mapped_held))
      << first_line({1'000'000, Source::address_space});
}

}  // namespace
