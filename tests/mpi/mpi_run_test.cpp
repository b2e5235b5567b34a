// vmpray under mpirun: the image is byte-identical to the one-process
// run's for 1 to 4 ranks (uneven splits too), over shared memory and over
// TCP on loopback, with scenes from standard input and from .gz files; only
// rank 0 writes; the report names the ranks; what cannot run over several
// ranks is refused in one line before any work; bad input on rank 0, and a
// rank killed mid-run, end the whole job non-zero within seconds, with no
// output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/scratch.hpp"

namespace {

using test::Outcome;
using test::read_file;

// Open MPI as root, more ranks than cores, and no single-copy mechanism
// (containers often forbid the ptrace it needs).
const char* const mpi_environment =
    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
    "OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_rmaps_base_oversubscribe=1";

struct Transport {
  const char* name;
  const char* mca;
};
const Transport shared_memory{"shared memory", "--mca btl self,vader"};
const Transport tcp{"tcp", "--mca btl self,tcp --mca btl_tcp_if_include lo"};

class Mpirun : public test::ScratchTest {
 protected:
  Mpirun() : ScratchTest("vmpray_mpi_") {}

  // `mpirun -np ranks [launch] vmpray args` in the scratch directory, ended
  // after 120 s at most; stdin from `input` (empty: /dev/null). timeout says
  // on stderr when it signals the job (timed_out()).
  Outcome mpirun(int ranks, const Transport& via, const std::string& args, const std::string& input = "",
                 const std::string& launch = "") const {
    const std::string cmd = "cd '" + dir_.string() + "' && " + mpi_environment + " timeout -v -k 10 120 " + MPIEXEC +
                            " -np " + std::to_string(ranks) + " " + via.mca + " " + launch + " " + test::vmpray_binary() +
                            " " + args + " >stdout.txt 2>stderr.txt <" + (input.empty() ? "/dev/null" : input);
    const int status = std::system(cmd.c_str());
    return {WEXITSTATUS(status), read_file(dir_ / "stdout.txt"), read_file(dir_ / "stderr.txt")};
  }

  // Whether the job outlived its 120 s and timeout signalled it: the exit
  // code cannot tell, since a job whose rank died of SIGKILL exits 137 too.
  static bool timed_out(const Outcome& r) { return r.err.find("timeout: sending signal") != std::string::npos; }

  // The lines vmpray itself wrote (mpirun adds its own).
  static std::vector<std::string> vmpray_lines(const std::string& err) {
    std::vector<std::string> lines;
    std::istringstream in(err);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("vmpray: ", 0) == 0) lines.push_back(line);
    return lines;
  }

  std::string files_here() const {
    std::vector<std::string> names;
    for (const auto& entry : test::fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    std::string all;
    for (const auto& n : names) all += n + " ";
    return all;
  }
};

TEST_F(Mpirun, ImageIsByteIdenticalToOneProcessOverEveryRankCountAndTransport) {
  struct Case {
    int ranks;
    const Transport* via;
    std::string machine;
  };
  const std::vector<Case> cases{
      {1, &shared_memory, "--topology hypercube:4"},
      {2, &shared_memory, "--topology hypercube:4"},
      {2, &tcp, "--topology hypercube:6 --schedule static --threads 1"},
      {3, &shared_memory, "--topology mesh:4x4 --cache-pages 1"},
      {4, &tcp, "--topology hypercube:4 --schedule dynamic"},
      {4, &shared_memory, "--topology hypercube:6 --threads 2 --cache-pages 1000"},
      {3, &tcp, "--topology torus:3x3 --schedule affinity"},
      {2, &shared_memory, "--topology ring:16 --threads 2 --workers-per-node 2"},
      {4, &shared_memory, "--topology complete:8 --schedule static"},
  };
  const std::string scene = "teapot:3 --width 40 --height 40 -q";
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.ranks) + " ranks over " + c.via->name + ": " + c.machine);
    ASSERT_EQ(run_vmpray(scene + " " + c.machine + " -o one.png").exit_code, 0);
    const Outcome split = mpirun(c.ranks, *c.via, scene + " " + c.machine + " -o split.png");
    ASSERT_EQ(split.exit_code, 0) << split.err;
    EXPECT_EQ(read_file(dir_ / "split.png"), read_file(dir_ / "one.png"));
  }
}

TEST_F(Mpirun, ReadsTheSceneFromStandardInputAndFromGzipOnRankZero) {
  const std::string balls = test::shared_scenes() + "/balls-s1.nff";
  const std::string teapot = test::shared_scenes() + "/teapot-s7.nff.gz";
  const std::string size = " --width 48 --height 48 -q --topology hypercube:3";
  ASSERT_EQ(run_vmpray("'" + balls + "'" + size + " -o one.png").exit_code, 0);
  Outcome split = mpirun(3, shared_memory, "-" + size + " -o split.png", balls);
  ASSERT_EQ(split.exit_code, 0) << split.err;
  EXPECT_EQ(read_file(dir_ / "split.png"), read_file(dir_ / "one.png"));
  ASSERT_EQ(run_vmpray("'" + teapot + "'" + size + " -o one.png").exit_code, 0);
  split = mpirun(2, tcp, "'" + teapot + "'" + size + " -o split.png");
  ASSERT_EQ(split.exit_code, 0) << split.err;
  EXPECT_EQ(read_file(dir_ / "split.png"), read_file(dir_ / "one.png"));
}

TEST_F(Mpirun, OnlyRankZeroWritesAndTheReportNamesTheRanks) {
  const Outcome r = mpirun(3, shared_memory,
                           "teapot:2 --width 32 --height 32 --topology mesh:4x4 --stats s.json --report run.html");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(files_here(), "run.html s.json stderr.txt stdout.txt teapot-2.png ");
  // The page has the ranks' table: a row per rank with its block of nodes.
  const std::string html = read_file(dir_ / "run.html");
  EXPECT_NE(html.find("<caption>Per MPI rank (10 links cut)</caption>"), std::string::npos);
  for (const char* block : {">0-4</td>", ">5-9</td>", ">10-15</td>"})
    EXPECT_NE(html.find(block), std::string::npos) << block;
  // The summary, printed once, with one row per rank: 16 nodes in blocks
  // of 5, 5 and 6, strips of rows that end inside a row.
  EXPECT_NE(r.out.find("ranks          3 processes, 10 of 24 links cut"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0-4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("10-15"), std::string::npos) << r.out;
  const std::string json = read_file(dir_ / "s.json");
  EXPECT_NE(json.find("\"cut_links\": 10"), std::string::npos);
  for (const char* rank : {"\"rank\": 0,", "\"rank\": 1,", "\"rank\": 2,"})
    EXPECT_NE(json.find(rank), std::string::npos) << rank;
  EXPECT_EQ(r.err, "");
}

TEST_F(Mpirun, RefusesWhatCannotRunOverSeveralRanksInOneLine) {
  struct Case {
    std::string args;
    std::string says;
    int ranks = 2;
  };
  const std::vector<Case> cases{
      {"--timing virtual", "--timing virtual cannot run over several processes"},
      {"--compare-serial", "--compare-serial cannot run over several processes"},
      {"--single", "--single renders in one process"},
      {"--topology hypercube:1", "3 MPI ranks for a machine of 2 nodes", 3},
      {"sweep nodes", "sweep runs its points in one process"},
      {"--grain 0", "--grain"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const Outcome r = mpirun(c.ranks, shared_memory, c.args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    const auto lines = vmpray_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_NE(lines[0].find(c.says), std::string::npos) << lines[0];
    EXPECT_EQ(files_here(), "stderr.txt stdout.txt ");
  }
}

TEST_F(Mpirun, BadInputOnRankZeroEndsEveryRankWithOneLine) {
  {
    std::ofstream(dir_ / "bad.nff") << "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n"
                                    << "l 1 1 1\nf 1 0 0 1 0 0 0 1\ns 0 0 zero 1\n";
  }
  const Outcome r = mpirun(3, tcp, "bad.nff -o out.png");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const auto lines = vmpray_lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_NE(lines[0].find("bad.nff:10"), std::string::npos) << lines[0];
  EXPECT_FALSE(test::fs::exists(dir_ / "out.png"));
}

TEST_F(Mpirun, ARankKilledMidRunEndsTheJobWithNoOutput) {
  // Rank 2 is killed half a second in; the render takes several seconds.
  const std::string launch =
      "sh -c 'if [ \"$OMPI_COMM_WORLD_RANK\" = 2 ]; then exec timeout -s KILL 0.5 \"$0\" \"$@\"; else exec \"$0\" "
      "\"$@\"; fi'";
  const auto start = std::chrono::steady_clock::now();
  const Outcome r = mpirun(3, shared_memory, "teapot:6 --width 1024 --height 1024 -q -o out.png", "", launch);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(r.exit_code, 0) << r.err;
  // A hang, whether the job then ended at timeout's TERM (124) or its KILL
  // (137, which is also mpirun's own code for a rank killed by SIGKILL).
  EXPECT_FALSE(timed_out(r)) << "the job outlived its timeout: " << r.err;
  // The promise is an end within seconds of the loss, not at the timeout.
  EXPECT_LT(seconds, 30.0) << "the job took " << seconds << " s to end after a rank was killed";
  EXPECT_FALSE(test::fs::exists(dir_ / "out.png"));
}

}  // namespace
