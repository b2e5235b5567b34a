// The summary's note on a machine whose threads did not have their cores
// (app/render/machine_summary.hpp): it appears when the threads' CPU time
// falls below 90% of their running and spinning time, names the share and
// the cause (more threads than CPUs, other programs, ranks), and says what
// to pass; never for one thread, nor when the threads had their cores or
// did nothing.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/render/machine_summary.hpp"

namespace {

csp::ThreadUse thread_use(double running, double spinning, double cpu) {
  csp::ThreadUse u;
  u.seconds = running + spinning + 0.1;
  u.running_seconds = running;
  u.spinning_seconds = spinning;
  u.sleeping_seconds = 0.1;
  u.idle_seconds = spinning + 0.1;
  u.cpu_seconds = cpu;
  return u;
}

TEST(BusyCores, ThreadsThatLostTheirCoresAreToldToBeFewer) {
  // Two threads that wanted a core 0.6 s each and had one 0.36 s and 0.40 s: 63%.
  const std::vector<csp::ThreadUse> busy = {thread_use(0.5, 0.1, 0.36), thread_use(0.45, 0.15, 0.40)};
  const std::string note = app::busy_cores_note(busy, false, 2);
  EXPECT_EQ(note,
            "busy cores     the threads had a core 63% of the time they ran or spun: other programs took the cores, "
            "and fewer --threads may be faster (a machine's threads wait on each other)\n");
  const std::string over_ranks = app::busy_cores_note(busy, true, 2);
  EXPECT_NE(over_ranks.find("other programs, or ranks beyond the cores, took the cores"), std::string::npos);
  EXPECT_NE(over_ranks.find("fewer ranks or --threads may be faster"), std::string::npos);
  // Three threads on two CPUs: the run's own threads took turns.
  const std::vector<csp::ThreadUse> three = {busy[0], busy[1], busy[1]};
  EXPECT_NE(app::busy_cores_note(three, false, 2).find(": 3 threads took turns on the 2 CPUs this process may use, "
                                                       "and fewer --threads may be faster"),
            std::string::npos);
  // The same three threads on four CPUs: other programs.
  EXPECT_NE(app::busy_cores_note(three, false, 4).find(": other programs took the cores"), std::string::npos);
}

TEST(BusyCores, NoNoteForThreadsThatHadTheirCoresOrForOneThread) {
  // 95% of the time wanted: the OS's own noise, no note.
  EXPECT_EQ(app::busy_cores_note({thread_use(0.9, 0.1, 0.95), thread_use(0.8, 0.2, 0.95)}, false, 2), "");
  // At the threshold exactly: no note.
  EXPECT_EQ(app::busy_cores_note({thread_use(1.0, 0.0, 0.9), thread_use(1.0, 0.0, 0.9)}, false, 2), "");
  // One thread, however starved: nothing to make fewer.
  EXPECT_EQ(app::busy_cores_note({thread_use(1.0, 0.0, 0.2)}, false, 2), "");
  // Threads that neither ran nor spun (a run too short to measure).
  EXPECT_EQ(app::busy_cores_note({thread_use(0.0, 0.0, 0.0), thread_use(0.0, 0.0, 0.0)}, false, 2), "");
  EXPECT_EQ(app::busy_cores_note({}, false, 2), "");
}

}  // namespace
