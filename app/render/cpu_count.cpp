// Usable CPUs; see cpu_count.hpp.
#include "app/render/cpu_count.hpp"

#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>
#include <thread>

namespace app {
namespace {

// The CPUs of a quota file: v2's "QUOTA PERIOD" (or "max PERIOD": none), or
// v1's quota in one file (-1: none) over the period in another.
std::optional<double> read_quota(const std::filesystem::path& group, bool v2) {
  double quota = 0, period = 0;
  if (v2) {
    std::ifstream in(group / "cpu.max");
    std::string first;
    if (!(in >> first >> period) || first == "max") return std::nullopt;
    std::istringstream(first) >> quota;
  } else {
    std::ifstream quota_in(group / "cpu.cfs_quota_us"), period_in(group / "cpu.cfs_period_us");
    if (!(quota_in >> quota) || !(period_in >> period)) return std::nullopt;
  }
  if (!(quota > 0) || !(period > 0)) return std::nullopt;
  return quota / period;
}

bool lists_controller(std::string_view controllers, std::string_view wanted) {
  for (std::size_t at = 0; at <= controllers.size();) {
    const std::size_t comma = std::min(controllers.find(',', at), controllers.size());
    if (controllers.substr(at, comma - at) == wanted) return true;
    at = comma + 1;
  }
  return false;
}

unsigned affinity_cpus() {
  // Sets big enough for any machine this runs on; CPU_ALLOC takes a count.
  for (int cpus = 1024; cpus <= (1 << 16); cpus *= 4) {
    cpu_set_t* set = CPU_ALLOC(cpus);
    if (!set) break;
    const std::size_t size = CPU_ALLOC_SIZE(cpus);
    CPU_ZERO_S(size, set);
    const bool got = sched_getaffinity(0, size, set) == 0;
    const int count = got ? CPU_COUNT_S(size, set) : 0;
    CPU_FREE(set);
    if (got) return static_cast<unsigned>(std::max(count, 1));
    if (errno != EINVAL) break;  // EINVAL: the set was too small for the kernel's
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

std::optional<double> cgroup_cpu_quota(const std::filesystem::path& root, const std::string& membership) {
  std::optional<double> least;
  std::istringstream lines(membership);
  for (std::string line; std::getline(lines, line);) {
    // hierarchy-ID:controller-list:path; v2's one hierarchy has ID 0 and no controllers listed.
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string_view controllers = std::string_view(line).substr(first + 1, second - first - 1);
    const bool v2 = line.compare(0, first, "0") == 0 && controllers.empty();
    if (!v2 && !lists_controller(controllers, "cpu")) continue;
    const std::filesystem::path hierarchy = v2 ? root : root / "cpu";
    for (std::filesystem::path group = std::filesystem::path(line.substr(second + 1)).relative_path();;
         group = group.parent_path()) {
      if (const auto cpus = read_quota(hierarchy / group, v2)) least = std::min(least.value_or(*cpus), *cpus);
      if (group.empty()) break;
    }
  }
  return least;
}

unsigned usable_cpus() {
  unsigned cpus = affinity_cpus();
  std::ifstream membership_file("/proc/self/cgroup");
  std::ostringstream membership;
  membership << membership_file.rdbuf();
  if (const auto quota = cgroup_cpu_quota("/sys/fs/cgroup", membership.str()))
    cpus = std::min(cpus, static_cast<unsigned>(std::max(1.0, std::ceil(*quota))));
  return cpus;
}

}  // namespace app
