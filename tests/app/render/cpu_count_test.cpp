// The CPUs --threads 0 and --jobs 0 count: the affinity mask, cut down by a
// control group's CPU quota (fake cgroup trees here), and the binary run
// under taskset using no more threads than the one CPU it may use.
#include <gtest/gtest.h>
#include <sched.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "app/experiments/sweep.hpp"
#include "app/render/cpu_count.hpp"
#include "tests/support/scratch.hpp"

namespace {

class CpuQuota : public test::ScratchTest {
 protected:
  CpuQuota() : ScratchTest("vmpray_cpu_quota_") {}
  void write(const std::string& file, const std::string& value) {
    std::filesystem::create_directories((dir_ / file).parent_path());
    std::ofstream(dir_ / file) << value << "\n";
  }
};

// v2: "QUOTA PERIOD" in cpu.max, "max" for none; the least on the path up.
TEST_F(CpuQuota, V2TakesTheLeastQuotaOnThePathUpToTheRoot) {
  const std::string membership = "0::/batch.slice/job.scope\n";
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), std::nullopt) << "no quota files at all";
  write("batch.slice/job.scope/cpu.max", "max 100000");
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), std::nullopt) << "max is no quota";
  write("batch.slice/cpu.max", "300000 100000");
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), 3.0) << "a parent's quota binds its children";
  write("batch.slice/job.scope/cpu.max", "150000 100000");
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), 1.5);
}

// v1: the cpu controller's hierarchy, quota over period; -1 is none.
TEST_F(CpuQuota, V1DividesTheQuotaByThePeriod) {
  write("cpu/docker/abc/cpu.cfs_quota_us", "-1");
  write("cpu/docker/abc/cpu.cfs_period_us", "100000");
  const std::string membership = "4:memory:/docker/abc\n3:cpu,cpuacct:/docker/abc\n";
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), std::nullopt);
  write("cpu/docker/abc/cpu.cfs_quota_us", "50000");
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, membership), 0.5);
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, "3:cpuset:/docker/abc\n"), std::nullopt) << "not the cpu controller";
  EXPECT_EQ(app::cgroup_cpu_quota(dir_, "garbage\n"), std::nullopt);
}

TEST(UsableCpus, AtMostTheAffinityMask) {
  cpu_set_t set;
  ASSERT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  EXPECT_GE(app::usable_cpus(), 1u);
  EXPECT_LE(app::usable_cpus(), static_cast<unsigned>(CPU_COUNT(&set)));
}

class OneCpu : public test::ScratchTest {
 protected:
  OneCpu() : ScratchTest("vmpray_one_cpu_") {}
  // The shell running vmpray confined to CPU `cpu` (the first it may use), as taskset -c would.
  std::string confine() const {
    cpu_set_t set;
    sched_getaffinity(0, sizeof set, &set);
    int cpu = 0;
    while (!CPU_ISSET(cpu, &set)) ++cpu;
    return "taskset -p -c " + std::to_string(cpu) + " $$ >/dev/null";
  }
};

// `taskset -c N vmpray`: the processors go on one thread, not one per core
// of the machine, which would share the one CPU.
TEST_F(OneCpu, ThreadsZeroUsesTheCpusOfTheAffinityMask) {
  const test::Outcome r = run_vmpray("tetra:1 --nodes 4 --width 8 --height 8 -o out.png", "stdout.txt", confine());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("order, 1 thread, cache"), std::string::npos) << r.out;
}

// A sweep's --jobs 0 counts the same CPUs: here this thread's, confined to one.
TEST(UsableCpus, SweepJobsZeroUsesTheCpusOfTheAffinityMask) {
  cpu_set_t before, one;
  ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
  int cpu = 0;
  while (!CPU_ISSET(cpu, &before)) ++cpu;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
  const char* argv[] = {"sweep", "nodes", "--jobs", "0"};
  const unsigned jobs = app::parse_sweep_options(4, argv).jobs;
  const unsigned usable = app::usable_cpus();
  ASSERT_EQ(sched_setaffinity(0, sizeof before, &before), 0);
  EXPECT_EQ(usable, 1u);
  EXPECT_EQ(jobs, 1u);
}

}  // namespace
