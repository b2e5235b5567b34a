// The bridge (nodes/ranks/bridge.hpp) carrying a network split over
// in-process ranks, over a test Transport that wraps LocalTransportGroup
// and delays both sides: each message posted waits a seeded random number
// of progress() calls before it leaves, and each arrival a seeded random
// number of polls before it is handed over, each pair of ranks keeping its
// order as MPI does. Every node sends and receives, pausing before each
// packet as the seed says, and one node reads very slowly.
//
// What every seed must show: every packet arrives once, in order between
// each pair of nodes (so on every cut link), with its payload intact; on
// the wire no link ever has more than K packets posted beyond the credits
// posted back for it (nor credits beyond its packets), and no rank posts
// after its `end`; all-to-all traffic ends; a shutdown while packets are in
// flight, on one rank, on all at once or from outside the runtimes, ends
// every rank with no exception, no failure noted and no send pending. A
// watchdog stops a run that delivers no packet for 20 s (or runs 200 s),
// so a hang fails instead of stalling, and a run slowed by a busy machine
// is not taken for one.
// And the packets a rank sends in one pass of its thread leave together,
// while the answers to what arrives leave at once, without the gathering.
//
// A seed fixes the topology, the ranks, K, the threads, the traffic, the
// pauses, the delays each endpoint draws and whether the bridges gather;
// the threads' timing is the OS's, so a seed replays its case, not one
// exact schedule. Seeds as in
// tests/support/seeded_runs.hpp (VMPRAY_SCHEDULE_SEEDS,
// VMPRAY_SCHEDULE_FIRST_SEED); a failure prints its seed and the command
// that replays it.
#include "nodes/ranks/bridge.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/ranks/bridge_wire.hpp"
#include "nodes/ranks/rank_plan.hpp"
#include "nodes/ranks/transport.hpp"
#include "tests/support/seeded_runs.hpp"

namespace {

using nodes::Bytes;
using nodes::NodeId;
using nodes::Packet;
using nodes::Tag;
using std::chrono::microseconds;
using test::mix;
using test::Pacer;
using test::Pauses;

constexpr const char* program = "ranks_tests";
constexpr std::chrono::milliseconds run_limit{20000};

// ---- The wire's ledger: the credit protocol as seen on the wire ----

// Every bridge frame posted, decoded: per cut link, packets posted less
// credits posted back, which must stay within 0..K; nothing after `end`.
class WireLedger {
 public:
  WireLedger(int ranks, std::size_t capacity)
      : ranks_(ranks), capacity_(capacity), ended_(static_cast<std::size_t>(ranks * ranks), false) {}

  // Called by `from`'s endpoint as it posts `frame` to `to`.
  void posted(int from, int to, const Bytes& frame) {
    std::lock_guard<std::mutex> lk(mutex_);
    try {
      nodes::WireReader r(frame);
      const std::uint64_t before = packets_, credits_before = credits_;
      while (!r.done()) record(from, to, r);
      if (packets_ > before) ++frames_with_packets_[from];
      else if (credits_ > credits_before) ++frames_of_credits_[from];
    } catch (const std::exception& e) {
      fail("rank " + std::to_string(from) + " to " + std::to_string(to) + ": " + e.what());
    }
  }

  std::string error() const {
    std::lock_guard<std::mutex> lk(mutex_);
    return error_;
  }
  std::size_t peak() const {  // the most packets one link had out
    std::lock_guard<std::mutex> lk(mutex_);
    return peak_;
  }
  std::uint64_t packets() const {  // packet records posted
    std::lock_guard<std::mutex> lk(mutex_);
    return packets_;
  }
  std::uint64_t frames_with_packets(int from) const {  // frames `from` posted that carried packets
    std::lock_guard<std::mutex> lk(mutex_);
    const auto it = frames_with_packets_.find(from);
    return it == frames_with_packets_.end() ? 0 : it->second;
  }
  std::uint64_t frames_of_credits(int from) const {  // frames `from` posted with credits and no packet
    std::lock_guard<std::mutex> lk(mutex_);
    const auto it = frames_of_credits_.find(from);
    return it == frames_of_credits_.end() ? 0 : it->second;
  }
  // Whether every rank posted `end` to every other.
  bool all_ended() const {
    std::lock_guard<std::mutex> lk(mutex_);
    for (int a = 0; a < ranks_; ++a)
      for (int b = 0; b < ranks_; ++b)
        if (a != b && !ended_[static_cast<std::size_t>(a * ranks_ + b)]) return false;
    return true;
  }

 private:
  using Key = std::tuple<NodeId, NodeId, unsigned>;

  void record(int from, int to, nodes::WireReader& r) {
    const auto pair = static_cast<std::size_t>(from * ranks_ + to);
    if (ended_[pair]) throw std::logic_error("a record after its end");
    switch (static_cast<nodes::BridgeRecord>(r.get<std::uint8_t>())) {
      case nodes::BridgeRecord::packet: {
        const nodes::CutLink link = nodes::get_link(r);
        (void)nodes::get_packet(r);
        ++packets_;
        const std::int64_t out = ++out_[key(link)];
        peak_ = std::max(peak_, static_cast<std::size_t>(out));
        if (out > static_cast<std::int64_t>(capacity_))
          fail(describe(link) + ": " + std::to_string(out) + " packets out, beyond K = " + std::to_string(capacity_));
        break;
      }
      case nodes::BridgeRecord::credit: {
        const auto credit = nodes::get_fields<nodes::CreditRecord>(r);
        ++credits_;
        if (credit.count == 0) fail(describe(credit.link) + ": a credit record of 0");
        if ((out_[key(credit.link)] -= credit.count) < 0)
          fail(describe(credit.link) + ": more credits returned than packets sent");
        break;
      }
      case nodes::BridgeRecord::end:
        ended_[pair] = true;
        break;
      case nodes::BridgeRecord::abort:
        fail("an abort: " + nodes::get_fields<nodes::AbortRecord>(r).text);
        break;
      default:
        throw std::logic_error("an unknown record");
    }
  }
  static Key key(const nodes::CutLink& l) { return {l.from, l.to, l.buffer_class}; }
  static std::string describe(const nodes::CutLink& l) {
    return "link " + std::to_string(l.from) + "->" + std::to_string(l.to) + " class " + std::to_string(l.buffer_class);
  }
  void fail(const std::string& what) {
    if (error_.empty()) error_ = "on the wire, " + what;
  }

  const int ranks_;
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::map<Key, std::int64_t> out_;  // per cut link: packets posted less credits posted
  std::vector<bool> ended_;          // [from * ranks + to]: `end` posted
  std::size_t peak_ = 0;
  std::uint64_t packets_ = 0, credits_ = 0;  // packet and credit records posted
  std::map<int, std::uint64_t> frames_with_packets_;  // per sending rank
  std::map<int, std::uint64_t> frames_of_credits_;    // per sending rank: credits and no packet
  std::string error_;
};

// ---- The delaying transport ----

// How long one endpoint holds messages back: each is held a number of
// calls drawn from 0..max (none half the time).
struct Delays {
  unsigned max_progress = 0;  // sends: progress() calls before one leaves
  unsigned max_polls = 0;     // arrivals: poll() calls before one is handed over
};

// One rank's Transport: LocalTransportGroup's, with the bridge's messages
// held back on both sides, each pair of ranks in its order, and every
// bridge frame shown to the ledger as it is posted. Other tags pass at once.
class DelayedTransport final : public nodes::Transport {
 public:
  DelayedTransport(nodes::Transport& inner, WireLedger& ledger, Delays delays, std::uint64_t seed)
      : inner_(inner),
        ledger_(ledger),
        delays_(delays),
        rng_(seed),
        outbox_(static_cast<std::size_t>(inner.size())),
        inbox_(static_cast<std::size_t>(inner.size())) {}

  int rank() const override { return inner_.rank(); }
  int size() const override { return inner_.size(); }

  void post(int to, Tag tag, Bytes message) override {
    if (tag != Tag::bridge) return inner_.post(to, tag, std::move(message));
    if (to < 0 || to >= size() || to == rank()) throw std::out_of_range("delayed transport: no such peer");
    ledger_.posted(rank(), to, message);
    outbox_[static_cast<std::size_t>(to)].push_back(Held{hold(delays_.max_progress), std::move(message)});
  }

  std::optional<nodes::Incoming> poll(Tag tag) override {
    if (tag != Tag::bridge) return inner_.poll(tag);
    while (std::optional<nodes::Incoming> m = inner_.poll(tag))
      inbox_[static_cast<std::size_t>(m->from)].push_back(Held{hold(delays_.max_polls), std::move(m->bytes)});
    // Each poll counts down the first message from each rank; the first
    // one due, from the ranks in rotation, is handed over.
    for (auto& queue : inbox_)
      if (!queue.empty() && queue.front().calls > 0) --queue.front().calls;
    for (std::size_t k = 0; k < inbox_.size(); ++k) {
      const std::size_t from = (next_from_ + k) % inbox_.size();
      auto& queue = inbox_[from];
      if (queue.empty() || queue.front().calls > 0) continue;
      nodes::Incoming m{static_cast<int>(from), std::move(queue.front().bytes)};
      queue.pop_front();
      next_from_ = from + 1;
      return m;
    }
    return std::nullopt;
  }

  void progress() override {
    for (std::size_t to = 0; to < outbox_.size(); ++to) {
      auto& queue = outbox_[to];
      if (!queue.empty() && queue.front().calls > 0) --queue.front().calls;
      while (!queue.empty() && queue.front().calls == 0) {
        inner_.post(static_cast<int>(to), Tag::bridge, std::move(queue.front().bytes));
        queue.pop_front();
      }
    }
    inner_.progress();
  }

  std::size_t pending() const override {
    std::size_t n = inner_.pending();
    for (const auto& queue : outbox_) n += queue.size();
    return n;
  }

 private:
  struct Held {
    unsigned calls = 0;  // calls still to wait
    Bytes bytes;
  };
  unsigned hold(unsigned max) { return max == 0 || rng_() % 2 ? 0 : 1 + static_cast<unsigned>(rng_() % max); }

  nodes::Transport& inner_;
  WireLedger& ledger_;
  const Delays delays_;
  std::mt19937_64 rng_;
  std::vector<std::deque<Held>> outbox_;  // per rank: posted, not yet sent
  std::vector<std::deque<Held>> inbox_;   // per rank: arrived, not yet handed over
  std::size_t next_from_ = 0;
};

// ---- Cases ----

struct Case {
  topology::Topology topology = topology::Topology::ring(2);
  int ranks = 2;
  std::size_t capacity = 1;  // K
  unsigned threads = 1;      // per rank
  bool relays = false;       // links between a rank's threads through thread relays
  std::vector<std::vector<std::uint64_t>> packets;  // [from][to]
  std::vector<Pauses> send, receive;                // per node
  std::vector<Delays> delays;                       // per rank
  NodeId slow = 0;                                  // its receiver sleeps before every packet
  bool gathering = false;  // every bridge gathers its thread's pass, however cheap a message
};

std::string describe(const Case& c) {
  std::uint64_t packets = 0;
  for (const auto& row : c.packets)
    for (std::uint64_t n : row) packets += n;
  return c.topology.spec() + " on " + std::to_string(c.ranks) + " ranks, K=" + std::to_string(c.capacity) +
         " threads=" + std::to_string(c.threads) + (c.relays ? " relays" : "") + " packets=" + std::to_string(packets) +
         " slow node " + std::to_string(c.slow) + (c.gathering ? " gathering" : "");
}

Case draw_case(std::uint64_t seed, std::uint64_t max_per_pair) {
  std::mt19937_64 rng(seed);
  Case c;
  switch (rng() % 7) {
    case 0: c.topology = topology::Topology::complete(4), c.ranks = 2; break;
    case 1: c.topology = topology::Topology::complete(5), c.ranks = 3; break;
    case 2: c.topology = topology::Topology::ring(6), c.ranks = 3; break;
    case 3: c.topology = topology::Topology::hypercube(3), c.ranks = 2; break;
    case 4: c.topology = topology::Topology::hypercube(3), c.ranks = 4; break;
    case 5: c.topology = topology::Topology::mesh(3, 2), c.ranks = 2; break;
    default: c.topology = topology::Topology::torus(3, 3), c.ranks = 3; break;
  }
  c.capacity = 1 + rng() % 5;
  c.threads = 1 + static_cast<unsigned>(rng() % 2);
  c.relays = rng() % 2 == 0;
  const std::size_t n = c.topology.size();
  c.packets.assign(n, std::vector<std::uint64_t>(n, 0));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
      if (a != b) c.packets[a][b] = rng() % (max_per_pair + 1);
  for (std::size_t k = 0; k < n; ++k) {
    c.send.push_back(test::draw_pauses(rng));
    c.receive.push_back(test::draw_pauses(rng));
  }
  for (int r = 0; r < c.ranks; ++r) {
    const unsigned most = static_cast<unsigned>(rng() % 12);
    c.delays.push_back(Delays{most, static_cast<unsigned>(rng() % 12)});
  }
  c.slow = static_cast<NodeId>(rng() % n);
  c.receive[c.slow] = Pauses{0, 1, microseconds(20 + rng() % 80)};
  c.gathering = rng() % 2 == 0;
  return c;
}

// Packet `seq` from `from` to `to`: its payload (mostly under 64 bytes,
// one in sixteen a few kilobytes, past a frame's 3 KB) follows from the
// three, so that the receiver can check it whole.
Packet make_packet(NodeId from, NodeId to, std::uint64_t seq) {
  const std::uint64_t h = mix((std::uint64_t{from} << 40) ^ (std::uint64_t{to} << 20) ^ seq);
  Packet p;
  p.destination = to;
  p.kind = nodes::kind_traffic;
  p.id = seq;
  p.payload.resize(h % 16 == 0 ? 1000 + h % 4000 : h % 64);
  for (std::size_t i = 0; i < p.payload.size(); ++i) p.payload[i] = static_cast<std::byte>((h >> (i % 57)) ^ i);
  return p;
}

// ---- One run ----

// What every rank shares: the wire, the ledger, the counts.
struct World {
  World(const Case& c) : plan(c.topology, c.ranks), group(c.ranks), ledger(c.ranks, c.capacity) {}
  nodes::RankPlan plan;
  nodes::LocalTransportGroup group;
  WireLedger ledger;
  std::atomic<std::uint64_t> remaining{0};  // packets not yet received, machine-wide
  std::atomic<std::uint64_t> delivered{0};  // packets received, machine-wide
};

// One rank: its runtime, the nodes it runs, its bridge over its endpoint.
struct Rank {
  Rank(const Case& c, World& world, int r, std::uint64_t seed)
      : endpoint(world.group.rank(r), world.ledger, c.delays[static_cast<std::size_t>(r)], mix(seed * 8 + r)),
        runtime(runtime_options(c)),
        net(runtime, c.topology, network_options(c, world.plan, r)),
        bridge(endpoint, world.plan, net, local_failure, remote_failure, counters) {
    if (c.gathering) bridge.set_gathering({microseconds(200), std::chrono::nanoseconds(0)});
  }

  static csp::RuntimeOptions runtime_options(const Case& c) {
    csp::RuntimeOptions o;
    o.threads = c.threads;
    o.shared_cores = true;
    return o;
  }
  static nodes::NetworkOptions network_options(const Case& c, const nodes::RankPlan& plan, int r) {
    nodes::NetworkOptions o;
    o.buffer_capacity = c.capacity;
    o.relay_between_threads = c.relays;
    o.local = [&plan, r](NodeId n) { return plan.runs(r, n); };
    o.placement = [&plan, r, threads = c.threads](NodeId n) {
      return static_cast<unsigned>((n - plan.first(r)) * threads / plan.count(r));
    };
    return o;
  }

  DelayedTransport endpoint;
  nodes::FailureNote local_failure, remote_failure;
  nodes::BridgeCounters counters;
  csp::Runtime runtime;
  nodes::Network net;
  nodes::Bridge bridge;
  std::string error;  // what ended its run, if anything did
};

// Every rank of a case, run each on a thread of its own under one watchdog.
class Machine {
 public:
  Machine(const Case& c, std::uint64_t seed) : case_(c), world_(c) {
    for (int r = 0; r < c.ranks; ++r) ranks_.push_back(std::make_unique<Rank>(c, world_, r, seed));
    for (const auto& row : c.packets)
      for (std::uint64_t n : row) world_.remaining += n;
  }

  World& world() { return world_; }
  Rank& rank(int r) { return *ranks_[static_cast<std::size_t>(r)]; }
  Rank& rank_of(NodeId n) { return rank(world_.plan.rank_of(n)); }

  // Spawns the bridges and runs every rank to its end; the first error of
  // any rank or of the wire, or "".
  std::string run(const std::string& what) {
    for (auto& r : ranks_)
      r->runtime.spawn("bridge", r->net.thread_of(world_.plan.first(r->endpoint.rank())),
                       [&bridge = r->bridge] { bridge.run(); });
    test::Watchdog dog(
        run_limit,
        [this] {
          for (auto& r : ranks_) r->net.shutdown();
        },
        what, [this] { return world_.delivered.load(std::memory_order_relaxed); });
    std::vector<std::thread> threads;
    for (auto& r : ranks_)
      threads.emplace_back([&r = *r] {
        try {
          r.runtime.run();
        } catch (const std::exception& e) {
          r.error = e.what();
        }
      });
    for (auto& t : threads) t.join();
    if (dog.fired())
      return "no packet delivered for " + std::to_string(run_limit.count()) + " ms, or no end within ten times that";
    if (!world_.ledger.error().empty()) return world_.ledger.error();
    for (int k = 0; k < case_.ranks; ++k) {
      Rank& r = rank(k);
      const std::string on = "rank " + std::to_string(k) + ": ";
      if (!r.error.empty()) return on + r.error;
      if (r.local_failure.get()) return on + "a local failure noted: " + r.local_failure.get()->second;
      if (r.remote_failure.get()) return on + "a remote failure noted: " + r.remote_failure.get()->second;
      if (r.endpoint.pending() > 0) return on + std::to_string(r.endpoint.pending()) + " sends still pending";
    }
    if (!world_.ledger.all_ended()) return "a rank did not post `end` to every other";
    return "";
  }

 private:
  const Case& case_;
  World world_;
  std::vector<std::unique_ptr<Rank>> ranks_;
};

// A failure in a process ends its rank's network, as a split machine does,
// so that the others end too and the run reports it.
void spawn_checked(Rank& rank, const std::string& name, unsigned thread, std::function<void()> body,
                   csp::Priority priority) {
  rank.runtime.spawn(
      name, thread,
      [&rank, body = std::move(body)] {
        try {
          body();
        } catch (const csp::Poisoned&) {
          throw;
        } catch (...) {
          rank.net.shutdown();
          throw;
        }
      },
      priority);
}

// Node n's sender: its packets to every other node, destinations in a
// drawn order, each destination's in sequence; `forever`: one to each
// other node per round, round after round, until poisoned.
void spawn_sender(Machine& m, const Case& c, NodeId n, std::uint64_t seed, bool forever) {
  Rank& rank = m.rank_of(n);
  std::mt19937_64 rng(mix(seed * 64 + 2 * n + 1));
  const csp::Priority priority = test::draw_priority(rng);
  std::vector<NodeId> order;
  for (NodeId to = 0; to < c.topology.size(); ++to)
    for (std::uint64_t k = forever ? (to != n) : c.packets[n][to]; k > 0; --k) order.push_back(to);
  Pacer pacer(c.send[n], mix(seed * 64 + 2 * n));
  spawn_checked(
      rank, "send " + std::to_string(n), rank.net.thread_of(n),
      [&c, n, forever, order, rng, pacer, out = rank.net.injector(n)]() mutable {
        std::vector<std::uint64_t> next(c.topology.size(), 0);
        do {
          std::shuffle(order.begin(), order.end(), rng);
          for (NodeId to : order) {
            pacer.pause();
            out.write(make_packet(n, to, next[to]++));
          }
        } while (forever);
      },
      priority);
}

// Node n's receiver: checks that each packet is the next from its source,
// intact; reads `expected` packets (or until poisoned), and the last
// receiver of the machine to finish shuts its rank's network down.
void spawn_receiver(Machine& m, const Case& c, NodeId n, std::uint64_t seed, std::optional<std::uint64_t> expected) {
  Rank& rank = m.rank_of(n);
  Pacer pacer(c.receive[n], mix(seed * 64 + 2 * n + 33));
  spawn_checked(
      rank, "receive " + std::to_string(n), rank.net.thread_of(n),
      [&c, &m, &rank, n, expected, pacer, in = rank.net.port(n)]() mutable {
        std::vector<std::uint64_t> next(c.topology.size(), 0);
        for (std::uint64_t k = 0; !expected || k < *expected; ++k) {
          pacer.pause();
          const Packet p = in.read();
          const std::string where = "node " + std::to_string(n) + " from " + std::to_string(p.source) + ": ";
          if (p.source >= next.size() || p.destination != n || p.kind != nodes::kind_traffic)
            throw std::logic_error(where + "a packet not sent to it");
          if (p.id != next[p.source])
            throw std::logic_error(where + "packet " + std::to_string(p.id) + " where " +
                                   std::to_string(next[p.source]) + " was due");
          if (p.payload != make_packet(p.source, n, p.id).payload)
            throw std::logic_error(where + "packet " + std::to_string(p.id) + " arrived altered");
          ++next[p.source];
          m.world().delivered.fetch_add(1, std::memory_order_relaxed);
          if (expected && m.world().remaining.fetch_sub(1) == 1) rank.net.shutdown();
        }
      },
      csp::Priority::high);
}

std::uint64_t packets_to(const Case& c, NodeId n) {
  std::uint64_t total = 0;
  for (const auto& row : c.packets) total += row[n];
  return total;
}

// The watchdog these runs go under: a run that goes on raising its
// progress count past the limit is not stopped; one whose count stands
// still is stopped once the limit has passed since the count last moved;
// one that raises it without end is stopped at ten limits.
TEST(BridgeWatchdog, StopsARunThatMakesNoProgressAndNotOneThatIsSlow) {
  using namespace std::chrono_literals;
  const auto limit = 200ms;
  // A run of at most `runs` that looks every 10 ms whether it was stopped
  // and, when it `moves`, raises its count each time.
  const auto watched = [&](std::chrono::milliseconds runs, bool moves) {
    std::atomic<std::uint64_t> count{0};
    std::atomic<bool> stopped{false};
    const auto start = std::chrono::steady_clock::now();
    test::Watchdog dog(limit, [&] { stopped = true; }, "test", [&] { return count.load(); });
    while (!stopped && std::chrono::steady_clock::now() - start < runs) {
      std::this_thread::sleep_for(10ms);
      if (moves) ++count;
    }
    return std::pair{dog.fired(), std::chrono::steady_clock::now() - start};
  };
  const auto [slow_fired, slow_took] = watched(3 * limit, true);  // three limits, moving on
  EXPECT_FALSE(slow_fired);
  EXPECT_GE(slow_took, 3 * limit);
  const auto [still_fired, still_took] = watched(20 * limit, false);
  EXPECT_TRUE(still_fired);
  EXPECT_GE(still_took, limit);
  EXPECT_LT(still_took, 10 * limit);
  const auto [endless_fired, endless_took] = watched(20 * limit, true);  // moving on without end
  EXPECT_TRUE(endless_fired);
  EXPECT_GE(endless_took, 10 * limit);
  EXPECT_LT(endless_took, 19 * limit);
}

// All-to-all traffic between every pair of nodes, K from 1 to 5, one or two
// threads per rank (relayed or not), each node's ends pausing at random,
// one node reading very slowly, every message held back at random: every
// packet arrives once, in order and intact, the wire keeps every link
// within its credits, every rank ends cleanly, and some link of some seed
// used all K of its credits.
TEST(Bridge, DelayedWireDeliversEveryPacketOnceInOrder) {
  const test::SeedRange seeds = test::seed_range(50);
  bool some_link_used_all = false;
  for (std::uint64_t seed = seeds.first; seed < seeds.first + seeds.count; ++seed) {
    const Case c = draw_case(seed, 6);
    const std::string where = test::replay_line(seed, program) + ", " + describe(c);
    Machine m(c, seed);
    std::uint64_t total = m.world().remaining.load();
    for (NodeId n = 0; n < c.topology.size(); ++n) {
      spawn_sender(m, c, n, seed, false);
      spawn_receiver(m, c, n, seed, packets_to(c, n));
    }
    if (total == 0) m.rank(0).runtime.spawn("end", 0, [&net = m.rank(0).net] { net.shutdown(); });
    const std::string error = m.run(where);
    ASSERT_EQ(error, "") << where;
    ASSERT_EQ(m.world().delivered.load(), total) << where;
    std::uint64_t sent = 0, received = 0;
    for (int r = 0; r < c.ranks; ++r) {
      sent += m.rank(r).counters.packets_sent;
      received += m.rank(r).counters.packets_received;
    }
    ASSERT_EQ(sent, m.world().ledger.packets()) << where;
    ASSERT_EQ(received, sent) << where;
    some_link_used_all |= m.world().ledger.peak() == c.capacity;
  }
  EXPECT_TRUE(some_link_used_all || seeds.count < 20) << "no seed filled a cut link to K: the traffic is too light";
}

// Shutdown while packets are in flight (every node sends until poisoned):
// on one rank once a drawn number of packets has arrived, on every rank at
// that point, or from a thread outside the runtimes after a drawn time.
// Every rank ends without an exception or a failure noted and with nothing
// pending, every rank posts `end` to every other, and what arrived before
// the end came once, in order and intact.
TEST(Bridge, ShutdownInFlightEndsEveryRank) {
  const test::SeedRange seeds = test::seed_range(50);
  for (std::uint64_t seed = seeds.first; seed < seeds.first + seeds.count; ++seed) {
    const Case c = draw_case(seed, 1);
    std::mt19937_64 rng(mix(seed + 5));
    const int how = static_cast<int>(rng() % 3);  // 0: one rank, 1: every rank, 2: from outside
    const int first_rank = static_cast<int>(rng() % static_cast<std::uint64_t>(c.ranks));
    const std::uint64_t after_packets = rng() % (8 * c.capacity * c.topology.size());
    const microseconds after_time(rng() % 3000);
    const std::string where = test::replay_line(seed, program) + ", " + describe(c) + ", shut down " +
                              (how == 2   ? "from outside after " + std::to_string(after_time.count()) + " us"
                               : how == 1 ? "on every rank after " + std::to_string(after_packets) + " packets"
                                          : "on rank " + std::to_string(first_rank) + " after " +
                                                std::to_string(after_packets) + " packets");
    Machine m(c, seed);
    for (NodeId n = 0; n < c.topology.size(); ++n) {
      spawn_sender(m, c, n, seed, true);
      spawn_receiver(m, c, n, seed, std::nullopt);
    }
    for (int r = 0; r < c.ranks; ++r) {
      if (how == 2 || (how == 0 && r != first_rank)) continue;
      Rank& rank = m.rank(r);
      rank.runtime.spawn("shut down", 0, [&rank, &m, after_packets] {
        while (m.world().delivered.load(std::memory_order_relaxed) < after_packets && !rank.net.shut_down())
          csp::sleep_for(microseconds(20));
        rank.net.shutdown();
      });
    }
    std::thread outside;
    if (how == 2)
      outside = std::thread([&m, first_rank, after_time] {
        std::this_thread::sleep_for(after_time);
        m.rank(first_rank).net.shutdown();
      });
    const std::string error = m.run(where);
    if (outside.joinable()) outside.join();
    ASSERT_EQ(error, "") << where;
  }
}

// Four low-priority processes of rank 0, each on its first turn after the
// one before has ended, send a packet each over four cut links: the first
// wakes the bridge, which lets the others run before it sends, and the four
// leave in one message once the thread has nothing else to run. With no
// gathering window each leaves alone, in a message of its own.
TEST(Bridge, ThePacketsOfOnePassLeaveInOneMessage) {
  for (const microseconds window : {microseconds(60'000'000), microseconds(0)}) {
    Case c;
    c.topology = topology::Topology::hypercube(3);
    c.capacity = 2;
    c.packets.assign(8, std::vector<std::uint64_t>(8, 0));
    for (NodeId n = 0; n < 4; ++n) c.packets[n][n + 4] = 1;
    c.send.assign(8, Pauses{});
    c.receive.assign(8, Pauses{});
    c.delays.assign(2, Delays{});
    Machine m(c, 1);
    Rank& sending = m.rank(0);
    sending.bridge.set_gathering({window, std::chrono::nanoseconds(0)});
    for (NodeId n = 0; n < 4; ++n) {
      spawn_checked(
          sending, "send " + std::to_string(n), sending.net.thread_of(n),
          [n, out = sending.net.injector(n)]() mutable {
            csp::yield();
            out.write(make_packet(n, n + 4, 0));
          },
          csp::Priority::low);
      spawn_receiver(m, c, n + 4, 1, 1);
    }
    const std::string where = "a window of " + std::to_string(window.count()) + " us";
    ASSERT_EQ(m.run(where), "") << where;
    EXPECT_EQ(m.world().ledger.packets(), 4u) << where;
    EXPECT_EQ(m.world().ledger.frames_with_packets(0), window.count() > 0 ? 1u : 4u) << where;
  }
}

// Two nodes on a ring split over two ranks, K = 2, `exchanges` packets each way.
Case ping_pong_case(std::uint64_t exchanges) {
  Case c;
  c.topology = topology::Topology::ring(2);
  c.capacity = 2;
  c.packets = {{0, exchanges}, {exchanges, 0}};
  c.send.assign(2, Pauses{});
  c.receive.assign(2, Pauses{});
  c.delays.assign(2, Delays{});
  return c;
}

// Node 0 on rank 0 sends a packet to node 1 on rank 1 and waits for the
// answer, `exchanges` times, then shuts its network down; node 1 answers
// each at once.
void spawn_ping_pong(Machine& m, std::uint64_t exchanges) {
  Rank& asking = m.rank(0);
  Rank& answering = m.rank(1);
  spawn_checked(
      asking, "ask", asking.net.thread_of(0),
      [&m, &asking, exchanges, out = asking.net.injector(0), in = asking.net.port(0)]() mutable {
        for (std::uint64_t k = 0; k < exchanges; ++k) {
          out.write(make_packet(0, 1, k));
          if (in.read().id != k) throw std::logic_error("an answer out of turn");
        }
        m.world().remaining = 0;
        asking.net.shutdown();
      },
      csp::Priority::high);
  spawn_checked(
      answering, "answer", answering.net.thread_of(1),
      [out = answering.net.injector(1), in = answering.net.port(1)]() mutable {
        for (std::uint64_t k = 0;; ++k) {
          if (in.read().id != k) throw std::logic_error("a question out of turn");
          out.write(make_packet(1, 0, k));
        }
      },
      csp::Priority::high);
}

// A ping-pong of 200 exchanges. With K = 2 each packet delivered makes half
// of K owed, so without a round's wait every credit would leave alone
// before the answer it called for; with it, the credit rides with the
// answer. (A slow machine may let a round end by the poll interval first,
// so the test asks for most credits, not all, to ride.)
TEST(Bridge, ACreditRidesWithTheAnswerToItsPacket) {
  constexpr std::uint64_t exchanges = 200;
  const Case c = ping_pong_case(exchanges);
  Machine m(c, 1);
  spawn_ping_pong(m, exchanges);
  ASSERT_EQ(m.run("ping-pong"), "");
  EXPECT_GE(m.world().ledger.frames_with_packets(1), exchanges - 1);
  EXPECT_LT(m.world().ledger.frames_of_credits(1), exchanges / 4);
}

// A ping-pong of 50 exchanges where the answering rank gathers for a
// minute, and a process of low priority on its thread is always ready, so
// that a gathering bridge would wait out its whole window for every answer
// (and the run its watchdog). The bridge that delivers a question lets the
// answer be made first and posts it at once: the exchanges end.
TEST(Bridge, AnAnswerLeavesWithoutWaitingForTheGatheringWindow) {
  constexpr std::uint64_t exchanges = 50;
  const Case c = ping_pong_case(exchanges);
  Machine m(c, 1);
  Rank& answering = m.rank(1);
  answering.bridge.set_gathering({microseconds(60'000'000), std::chrono::nanoseconds(0)});
  spawn_ping_pong(m, exchanges);
  spawn_checked(
      answering, "busy", answering.net.thread_of(1),
      [&answering] {
        while (!answering.net.shut_down()) csp::yield();
      },
      csp::Priority::low);
  ASSERT_EQ(m.run("answers under a long gathering window"), "");
  EXPECT_GE(m.world().ledger.frames_with_packets(1), exchanges);
}

}  // namespace
