// The CPUs this process may use, for --threads 0 and a sweep's --jobs 0:
// those of its affinity mask (sched_getaffinity: what taskset, numactl and
// batch schedulers give it), or fewer when its control group's CPU quota
// allows less time than that (a container's --cpus): cgroup v2's cpu.max,
// v1's cpu.cfs_quota_us over cpu.cfs_period_us, the least on the group's
// path to the root. A quota of 1.5 CPUs counts as 2: the half still runs.
// std::thread::hardware_concurrency counts the machine's CPUs, which a
// process confined to one of them would share among all its threads.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace app {

// The CPU time a second this process's control group may use, in CPUs:
// `root` is where the cgroup file system is mounted (/sys/fs/cgroup, holding
// v1's hierarchies by controller, or v2's if it is unified), `membership` the
// text of /proc/self/cgroup. nullopt when no group on the path sets a quota,
// or none can be read.
std::optional<double> cgroup_cpu_quota(const std::filesystem::path& root, const std::string& membership);

// The CPUs of the affinity mask, at most the quota (rounded up); at least 1.
unsigned usable_cpus();

}  // namespace app
