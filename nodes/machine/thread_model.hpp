// nodes::ThreadModel: a machine's render time on T runtime threads,
// predicted from runs on one and two threads (docs/performance.md, "A model
// for T threads"). Nodes sit on threads in subcubes and a page's owner is
// uniform over the nodes, so a miss crosses threads r = log2 T times; each
// crossing costs c of CPU and its packet a latency L; a thread of k pixel
// computers idles when a miss's round trip R = r L exceeds what the other
// k - 1 compute meanwhile, (k - 1) t with t = W / M:
//
//   time(T) = W / T + r M c / T + (M / T) max(0, R - (k - 1) t)
//
// W: the one-thread time; M: page misses (the same on any thread count); c
// fitted to two threads with many pixel computers each, L to two nodes on
// two threads. Counts that are not powers of two take r = log2 T too; more
// threads than pixel computers count as that many. Pure arithmetic.
#pragma once

namespace nodes {

struct ThreadModel {
  double work_seconds = 0;      // W: the machine's time on one thread
  double misses = 0;            // M: page misses over the run
  double crossing_seconds = 0;  // c: CPU a packet costs to cross threads
  double latency_seconds = 0;   // L: how long a crossing holds up its packet
  double pixel_computers = 1;   // nodes times pixel computers a node

  // What time(T) adds up, each in seconds.
  struct Parts {
    double work = 0;       // W / T
    double crossings = 0;  // r M c / T
    double idle = 0;       // (M / T) max(0, R - (k - 1) t)
    double total() const { return work + crossings + idle; }
  };
  Parts parts(unsigned threads) const;
  double predict(unsigned threads) const { return parts(threads).total(); }

  // c from one machine timed on one thread and on two (r = 1, no idling):
  // time(2) = W / 2 + M c / 2. Never below zero.
  static double fit_crossing(double one_thread_seconds, double two_thread_seconds, double misses);
  // L from two nodes (one pixel computer each) timed on one thread and on
  // two, given c: time(2) = W / 2 + M c / 2 + (M / 2) L. Never below zero.
  static double fit_latency(double one_thread_seconds, double two_thread_seconds, double misses,
                            double crossing_seconds);
};

}  // namespace nodes
