// commstime: cost of one channel communication and of one ALT.
//
// The network (Welch's occam benchmark):  Prefix -> Delta -> Succ -> Prefix,
// Delta -> Consume. Each cycle is four communications; Consume times N cycles.
// It runs on csp channels and, in the same run, on raw Boost.Fiber
// unbuffered_channel, on one thread and across two, and prints ns per
// communication and the ratio. Then it times ALT over 1, 4 and 16 channels,
// with the input already waiting (ready) and with the ALT parking (idle),
// for both ways an ALT can wait (relinking records on every channel, and the
// doorbell). In between, one network on every thread at once (1, 2, 4, ...
// up to the hardware's threads), none talking to another: what the threads
// cost each other through state the runtime shares between them. Last, what
// a write costs its sender when the reader is on another thread that is
// busy computing (no wake-up should reach the OS then), and the floor under
// every cross-thread figure: one cache line handed back and forth between
// two spinning threads, no runtime at all (a packet that crosses threads
// moves a few such lines: its ring slot, its payload, the ring's indices).
//
// One-thread figures are CPU time of that thread, two-thread ones wall time.
// Each figure is the best of several runs, alternating csp and raw, so that
// load from other programs on the machine hits both alike. Raw Boost across
// two threads can hang (Boost.Fiber issue #256), so it runs in a child
// process with a deadline and is reported as "hung" when it overruns.
//
// Usage: commstime [cycles] [runs]   (defaults 200000 and 5)
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <boost/fiber/all.hpp>
#include <chrono>
#include <limits>
#include <memory>
#include <optional>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "csp/csp.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double ns_per(Clock::duration d, long count) {
  return std::chrono::duration<double, std::nano>(d).count() / static_cast<double>(count);
}

// On one thread, the CPU time of that thread: other programs on a busy
// machine then inflate the figures far less than wall time would. Across
// threads, wall time (waiting for the other thread is part of the cost).
class Stopwatch {
 public:
  explicit Stopwatch(bool thread_cpu) : thread_cpu_(thread_cpu), start_(now()) {}
  Clock::duration elapsed() const { return now() - start_; }

 private:
  Clock::duration now() const {
    if (!thread_cpu_) return Clock::now().time_since_epoch();
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
  }
  bool thread_cpu_;
  Clock::duration start_;
};

// --- commstime on csp ----------------------------------------------------

// One commstime network: its channels, and the time its Consume measured.
struct Network {
  csp::Channel<long> a{"a"}, b{"b"}, c{"c"}, d{"d"};
  Clock::duration elapsed{};
};

// Spawns n's Prefix and Delta on thread `near` and its Succ and Consume on
// `far`. Consume times `cycles` cycles (the CPU time of its thread if
// `thread_cpu`, else wall time), then poisons c to shut the network down:
// poison spreads on first use.
void spawn_commstime(csp::Runtime& rt, Network& n, unsigned near, unsigned far, long cycles, bool thread_cpu) {
  rt.spawn("prefix", near, [in = n.d.reader(), out = n.a.writer()]() mutable {
    out.write(0);
    for (;;) out.write(in.read());
  });
  rt.spawn("delta", near, [in = n.a.reader(), to_succ = n.b.writer(), to_consume = n.c.writer()]() mutable {
    for (;;) {
      const long x = in.read();
      to_consume.write(x);
      to_succ.write(x);
    }
  });
  rt.spawn("succ", far, [in = n.b.reader(), out = n.d.writer()]() mutable {
    for (;;) out.write(in.read() + 1);
  });
  rt.spawn("consume", far, [in = n.c.reader(), &n, cycles, thread_cpu]() mutable {
    in.read();
    const Stopwatch watch(thread_cpu);
    for (long i = 0; i < cycles; ++i) in.read();
    n.elapsed = watch.elapsed();
    n.c.poison();
  });
}

// Runs rt to its end. The poisoned networks' other processes wait on ends
// nobody uses any more, which the runtime reports as a deadlock: by design.
void run_until_poisoned(csp::Runtime& rt) {
  try {
    rt.run();
  } catch (const csp::Deadlock&) {
  }
}

double csp_commstime(unsigned threads, long cycles) {
  Network n;
  csp::Runtime rt(threads);
  spawn_commstime(rt, n, 0, threads > 1 ? 1 : 0, cycles, threads == 1);  // Succ and Consume go across
  run_until_poisoned(rt);
  return ns_per(n.elapsed, 4 * cycles);
}

// One commstime network on each of `threads` threads, all at once: no
// process talks to another thread, so with no state shared between the
// threads each would run as fast as one thread alone. Wall time of the
// slowest network, ns per communication.
double csp_commstime_per_thread(unsigned threads, long cycles) {
  std::vector<std::unique_ptr<Network>> nets;
  csp::Runtime rt(threads);
  for (unsigned t = 0; t < threads; ++t)
    spawn_commstime(rt, *nets.emplace_back(std::make_unique<Network>()), t, t, cycles, false);
  run_until_poisoned(rt);
  Clock::duration slowest{};
  for (const auto& n : nets) slowest = std::max(slowest, n->elapsed);
  return ns_per(slowest, 4 * cycles);
}

void print_commstime_per_thread(long cycles, int runs) {
  const unsigned hardware = std::max(2u, std::thread::hardware_concurrency());
  std::vector<unsigned> counts{1};
  for (unsigned t = 2; t <= hardware; t *= 2) counts.push_back(t);
  if (counts.back() != hardware) counts.push_back(hardware);
  std::vector<double> best(counts.size(), std::numeric_limits<double>::max());
  for (int r = 0; r < runs; ++r)
    for (std::size_t i = 0; i < counts.size(); ++i)
      best[i] = std::min(best[i], csp_commstime_per_thread(counts[i], cycles));
  for (std::size_t i = 0; i < counts.size(); ++i)
    std::printf("%-8u %10.1f %9.2fx\n", counts[i], best[i], best[i] / best[0]);
}

// --- the same network on raw Boost.Fiber ---------------------------------

using RawChannel = boost::fibers::unbuffered_channel<long>;

void raw_thread(std::vector<std::function<void()>> bodies) {
  std::vector<boost::fibers::fiber> fibers;
  for (auto& body : bodies) fibers.emplace_back(std::move(body));
  for (auto& f : fibers) f.join();
}

double raw_commstime(unsigned threads, long cycles) {
  RawChannel a, b, c, d;
  Clock::duration elapsed{};
  auto prefix = [&] {
    a.push(0);
    long x;
    while (d.pop(x) == boost::fibers::channel_op_status::success) a.push(x);
  };
  auto delta = [&] {
    long x;
    while (a.pop(x) == boost::fibers::channel_op_status::success) {
      c.push(x);
      b.push(x);
    }
  };
  auto succ = [&] {
    long x;
    while (b.pop(x) == boost::fibers::channel_op_status::success) d.push(x + 1);
  };
  auto consume = [&] {
    c.value_pop();
    const Stopwatch watch(threads == 1);
    for (long i = 0; i < cycles; ++i) c.value_pop();
    elapsed = watch.elapsed();
    for (RawChannel* ch : {&a, &b, &c, &d}) ch->close();
  };
  if (threads == 1) {
    raw_thread({prefix, delta, succ, consume});
  } else {
    std::thread far(raw_thread, std::vector<std::function<void()>>{succ, consume});
    raw_thread({prefix, delta});
    far.join();
  }
  return ns_per(elapsed, 4 * cycles);
}

// Runs raw_commstime in a child process; nullopt if it does not finish in time.
std::optional<double> raw_commstime_guarded(unsigned threads, long cycles, std::chrono::seconds limit) {
  int fds[2];
  if (pipe(fds) != 0) return std::nullopt;
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    const double ns = raw_commstime(threads, cycles);
    const ssize_t written = write(fds[1], &ns, sizeof ns);
    _exit(written == sizeof ns ? 0 : 1);
  }
  close(fds[1]);
  pollfd pfd{fds[0], POLLIN, 0};
  double ns = 0;
  const bool done = child > 0 && poll(&pfd, 1, static_cast<int>(limit.count() * 1000)) == 1 &&
                    read(fds[0], &ns, sizeof ns) == static_cast<ssize_t>(sizeof ns);
  close(fds[0]);
  if (child > 0) {
    if (!done) kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
  }
  return done ? std::optional<double>(ns) : std::nullopt;
}

// --- ALT -----------------------------------------------------------------

// One writer feeds channel k of n (k cycles through all); the ALT selects and
// reads `count` times. Buffered channels keep input waiting (ready path);
// unbuffered ones make the ALT park before each input (idle path).
double alt_cost(std::size_t n, bool ready, long count, csp::Alt::Waiting waiting) {
  std::vector<csp::Channel<long>> chans;
  for (std::size_t i = 0; i < n; ++i) chans.emplace_back(std::to_string(i), ready ? 64 : 0);
  Clock::duration elapsed{};
  csp::Runtime rt(1);
  rt.spawn("writer", 0, [&chans, n, count] {
    std::vector<csp::Out<long>> outs;
    for (auto& c : chans) outs.push_back(c.writer());
    for (long i = 0; i < count; ++i) outs[static_cast<std::size_t>(i) % n].write(i);
  });
  rt.spawn("alt", 0, [&chans, &elapsed, count, waiting] {
    csp::Alt alt(waiting);
    std::vector<csp::In<long>> ins;
    for (auto& c : chans) ins.push_back(c.reader());
    for (auto& in : ins) alt.add_input(in);
    const Stopwatch watch(true);
    for (long i = 0; i < count; ++i) ins[alt.select()].read();
    elapsed = watch.elapsed();
  });
  rt.run();
  return ns_per(elapsed, count);
}

void print_commstime(unsigned threads, long cycles, int runs) {
  double ours = std::numeric_limits<double>::max();
  double raw = std::numeric_limits<double>::max();
  bool raw_hung = false;
  for (int r = 0; r < runs; ++r) {
    ours = std::min(ours, csp_commstime(threads, cycles));
    if (raw_hung) continue;
    const std::optional<double> ns = raw_commstime_guarded(threads, cycles, std::chrono::seconds(20));
    raw_hung = !ns;
    if (ns) raw = std::min(raw, *ns);
  }
  if (raw_hung) {
    std::printf("%-8u %10.1f %12s %8s\n", threads, ours, "hung", "-");
  } else {
    std::printf("%-8u %10.1f %12.1f %7.2fx\n", threads, ours, raw, raw / ours);
  }
}

void print_alt(std::size_t n, long count, int runs) {
  using Waiting = csp::Alt::Waiting;
  std::printf("%-8zu", n);
  for (Waiting waiting : {Waiting::relink, Waiting::doorbell}) {
    double ready = std::numeric_limits<double>::max();
    double idle = std::numeric_limits<double>::max();
    for (int r = 0; r < runs; ++r) {
      ready = std::min(ready, alt_cost(n, true, count, waiting));
      idle = std::min(idle, alt_cost(n, false, count, waiting));
    }
    std::printf(" %10.1f %10.1f", ready, idle);
  }
  std::printf("\n");
}

// --- hand-off to a busy thread -------------------------------------------

// What a packet costs its sender when it goes to a process on another
// thread that is busy: thread 1 runs a low-priority computation that
// yields only when csp::yield_requested() says so, and a reader; thread 0
// writes `count` values, each only once the reader has taken the one
// before, so that each write finds the reader parked (or about to park)
// and wakes it. Returns the wall ns per write call (the waits between
// writes not counted), the wakes thread 0 sent and how many of them found
// thread 1 asleep (a system call): with thread 1 busy, none should.
struct HandOff {
  double ns = 0;
  std::uint64_t wakes = 0;
  std::uint64_t asleep = 0;
};

HandOff hand_off_to_busy_thread(long count) {
  csp::Channel<long> c("c", 1);
  std::atomic<long> taken{0};
  Clock::duration elapsed{};
  csp::Runtime rt(2);
  rt.spawn("writer", 0, [out = c.writer(), count, &taken, &elapsed]() mutable {
    for (long i = 0; i < count; ++i) {
      while (taken.load(std::memory_order_acquire) < i) {
      }
      const auto start = Clock::now();
      out.write(i);
      elapsed += Clock::now() - start;
    }
  });
  rt.spawn("reader", 1, [in = c.reader(), count, &taken]() mutable {
    for (long i = 0; i < count; ++i) {
      in.read();
      taken.store(i + 1, std::memory_order_release);
    }
  });
  rt.spawn(
      "busy", 1,
      [&taken, count] {
        while (taken.load(std::memory_order_relaxed) < count)
          if (csp::yield_requested()) csp::yield();
      },
      csp::Priority::low);
  rt.run();
  const csp::ThreadUse use = rt.thread_use()[0];
  return {ns_per(elapsed, count), use.remote_wakes, use.sleepers_woken};
}

void print_hand_off(long count, int runs) {
  HandOff best{std::numeric_limits<double>::max(), 0, 0};
  for (int r = 0; r < runs; ++r) {
    const HandOff h = hand_off_to_busy_thread(count);
    if (h.ns < best.ns) best = h;
  }
  std::printf("%10.1f ns per write, %llu of %ld writes woke the reader, %llu of those found its thread asleep\n",
              best.ns, static_cast<unsigned long long>(best.wakes), count,
              static_cast<unsigned long long>(best.asleep));
}

// Two threads take turns writing one atomic word; wall ns per round trip
// (the line goes to the other core and comes back).
double line_round_trip(long count) {
  alignas(64) std::atomic<long> turn{0};
  std::thread other([&] {
    for (long i = 0; i < count; ++i) {
      while (turn.load(std::memory_order_acquire) != 2 * i + 1) {
      }
      turn.store(2 * i + 2, std::memory_order_release);
    }
  });
  const auto start = Clock::now();
  for (long i = 0; i < count; ++i) {
    turn.store(2 * i + 1, std::memory_order_release);
    while (turn.load(std::memory_order_acquire) != 2 * i + 2) {
    }
  }
  const auto elapsed = Clock::now() - start;
  other.join();
  return ns_per(elapsed, count);
}

void print_line_round_trip(long count, int runs) {
  double best = std::numeric_limits<double>::max();
  for (int r = 0; r < runs; ++r) best = std::min(best, line_round_trip(count));
  std::printf("%10.1f ns per round trip of a cache line between two threads\n", best);
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // show each line as it is measured
  const long cycles = argc > 1 ? std::atol(argv[1]) : 200000;
  const int runs = argc > 2 ? std::atoi(argv[2]) : 5;
  if (cycles <= 0 || runs <= 0) {
    std::fprintf(stderr, "usage: commstime [cycles > 0] [runs > 0]\n");
    return 2;
  }
  std::printf("commstime: %ld cycles of 4 communications, best of %d runs, ns per communication\n", cycles, runs);
  std::printf("(1 thread: CPU time of the thread; 2 threads: wall time)\n");
  std::printf("%-8s %10s %12s %8s\n", "threads", "csp", "raw boost", "raw/csp");
  for (unsigned threads : {1u, 2u}) print_commstime(threads, cycles, runs);
  std::printf("\nA network on every thread at once, wall ns per communication, best of %d runs\n", runs);
  std::printf("%-8s %10s %10s\n", "threads", "csp", "vs 1");
  print_commstime_per_thread(cycles, runs);
  std::printf("\nALT on one thread, CPU ns per select + read, best of %d runs\n", runs);
  std::printf("%-8s %21s %21s\n", "", "relink", "doorbell");
  std::printf("%-8s %10s %10s %10s %10s\n", "inputs", "ready", "idle", "ready", "idle");
  for (std::size_t n : {1u, 4u, 16u}) print_alt(n, cycles, runs);
  std::printf("\nHanding values to a process on a busy thread (wall ns per write), best of %d runs\n", runs);
  print_hand_off(cycles, runs);
  std::printf("\nThe machine's floor: one cache line between two spinning threads, best of %d runs\n", runs);
  if (std::thread::hardware_concurrency() >= 2) {
    print_line_round_trip(cycles, runs);
  } else {
    std::printf("(not measured: it needs two hardware threads)\n");
  }
  return 0;
}
