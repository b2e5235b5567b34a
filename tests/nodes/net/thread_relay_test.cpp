// ThreadRelays (nodes/net/thread_relay.hpp) driven directly, without
// routers: each relayed link has a sender process that writes its queue on
// one runtime thread (on about half the links, seeded, it hands a packet
// to the relays' sender() instead whenever that takes it at once, as a
// router's step does; on a quarter of the seeds the relays signal each
// batch instead of the threads polling their rings) and a receiver process
// that reads its input on another, and both pause before each packet for a
// seeded random number of yields, now and then a short sleep, so that the
// relays meet packets and credits in many orders. (The relays need csp::Arrivals, which only
// FifoScheduler gives, so the delays come from the links' ends rather than
// from csp::SeededScheduler.)
//
// What every seed must show: each packet arrives once, in its link's order,
// with every field intact (payload, shared bytes, route); a link never
// holds more than its three buffers of K packets (the queue, the relays'
// credits, the input), and one whose receiver stalls fills to 3K but for
// the credits held back (fewer than K/2); all-to-all traffic with one very
// slow reader ends; poison while packets are in flight, from a process or
// from outside the runtime, ends every process with no exception. A
// watchdog bounds each run's wall time, so a hang fails instead of
// stalling.
//
// A seed fixes the threads, K, the links, their traffic and every process's
// pauses; the OS still interleaves the threads, so a seed replays its case,
// not one exact schedule. Seeds as in tests/support/seeded_runs.hpp
// (VMPRAY_SCHEDULE_SEEDS, VMPRAY_SCHEDULE_FIRST_SEED); a failure prints its
// seed and the command that replays it.
#include "nodes/net/thread_relay.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/router.hpp"
#include "tests/support/seeded_runs.hpp"

namespace {

using nodes::Packet;
using nodes::ThreadRelays;
using test::draw_pauses;
using test::draw_priority;
using test::mix;
using test::Pacer;
using test::Pauses;
using Clock = std::chrono::steady_clock;
using std::chrono::microseconds;

constexpr const char* program = "net_tests";
constexpr std::chrono::milliseconds run_limit{20000};

struct LinkPlan {
  unsigned from = 0;  // the sender's thread
  unsigned to = 0;    // the receiver's thread
  std::uint64_t packets = 0;
  Pauses send, receive;
  csp::Priority send_priority = csp::Priority::high;
  csp::Priority receive_priority = csp::Priority::high;
  bool in_place = false;  // the sender hands packets to the relays' sender() when it takes them at once
};

struct Case {
  unsigned threads = 2;
  std::size_t capacity = 1;  // K: credits per link, and the capacity of its queue and input
  bool shared_cores = false;
  std::vector<LinkPlan> links;
  std::size_t slow = 0;  // the link whose receiver sleeps before every packet
  nodes::RelayWake wake = nodes::RelayWake::poll;
  std::uint64_t bound() const { return 3 * capacity; }  // packets one link can hold
};

std::string describe(const Case& c) {
  std::uint64_t packets = 0;
  for (const LinkPlan& l : c.links) packets += l.packets;
  return "threads=" + std::to_string(c.threads) + " K=" + std::to_string(c.capacity) +
         " links=" + std::to_string(c.links.size()) + " packets=" + std::to_string(packets) +
         " slow link " + std::to_string(c.slow) + (c.shared_cores ? " shared cores" : "") +
         (c.wake == nodes::RelayWake::signal ? " signalled" : "");
}

// Every ordered pair of threads joined by one or two links, each carrying
// `min_packets` to `max_packets` packets; one link's receiver very slow.
Case draw_case(std::uint64_t seed, std::uint64_t min_packets, std::uint64_t max_packets) {
  std::mt19937_64 rng(seed);
  Case c;
  c.threads = 2 + static_cast<unsigned>(rng() % 3);
  c.capacity = 1 + rng() % 5;
  c.shared_cores = rng() % 2 == 0;
  for (unsigned a = 0; a < c.threads; ++a)
    for (unsigned b = 0; b < c.threads; ++b)
      for (std::uint64_t k = a == b ? 0 : 1 + rng() % 2; k > 0; --k) {
        LinkPlan l{a, b, min_packets + rng() % (max_packets - min_packets + 1), draw_pauses(rng),
                   draw_pauses(rng), draw_priority(rng), draw_priority(rng)};
        c.links.push_back(l);
      }
  std::shuffle(c.links.begin(), c.links.end(), rng);
  c.slow = rng() % c.links.size();
  LinkPlan& slow = c.links[c.slow];
  slow.receive = Pauses{0, 1, microseconds(20 + rng() % 80)};
  slow.packets = std::max<std::uint64_t>(slow.packets, 2 * c.bound() + rng() % (2 * c.bound()));
  for (LinkPlan& l : c.links) l.in_place = rng() % 2 == 0;
  c.wake = rng() % 4 == 0 ? nodes::RelayWake::signal : nodes::RelayWake::poll;
  return c;
}

// Bytes that packets carry by reference (Packet::shared).
const std::array<std::byte, 256> shared_bytes = [] {
  std::array<std::byte, 256> b{};
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::byte>(i);
  return b;
}();

// Packet `id` of link `link`: every field, the payload (0 to 47 bytes:
// inside a ring entry up to 16, on the heap beyond), the shared bytes and,
// for a traced packet, a route (on the heap too) follow from the two, so
// that a receiver can check it whole.
Packet make_packet(std::size_t link, std::uint64_t id) {
  const std::uint64_t h = mix(link * 0x9e3779b97f4a7c15ULL + id + 1);
  Packet p;
  p.source = static_cast<nodes::NodeId>(link);
  p.destination = static_cast<nodes::NodeId>(h >> 40);
  p.kind = static_cast<std::uint8_t>(h >> 56);
  p.port = static_cast<std::uint16_t>(h);
  p.hops = static_cast<std::uint16_t>(h >> 16);
  p.traced = (h >> 32 & 7) == 0;
  p.recorded = (h >> 35 & 1) != 0;
  p.id = id;
  p.payload.resize(h % 48);
  for (std::size_t i = 0; i < p.payload.size(); ++i)
    p.payload[i] = static_cast<std::byte>(mix(h + i) & 0xff);
  p.shared = std::span<const std::byte>(shared_bytes).subspan(h >> 24 & 0x7f, h >> 36 & 0x7f);
  if (p.traced)
    for (std::uint64_t k = 0; k <= (h >> 44 & 3); ++k) p.route.push_back(static_cast<nodes::NodeId>(mix(h + k)));
  return p;
}

// Throws unless `p` is packet `id` of `link`, intact.
void check_packet(const Packet& p, std::size_t link, std::uint64_t id) {
  const Packet want = make_packet(link, id);
  const std::string where = "link " + std::to_string(link) + ": ";
  if (p.source != want.source || p.id != id)
    throw std::logic_error(where + "packet " + std::to_string(p.id) + " of link " + std::to_string(p.source) +
                           " arrived where packet " + std::to_string(id) + " was due");
  if (p.destination != want.destination || p.kind != want.kind || p.port != want.port || p.hops != want.hops ||
      p.traced != want.traced || p.recorded != want.recorded || p.payload != want.payload ||
      p.shared.data() != want.shared.data() || p.shared.size() != want.shared.size() || p.route != want.route)
    throw std::logic_error(where + "packet " + std::to_string(id) + " arrived altered");
}

// One relayed link: its two channels and what its ends have done.
struct LinkState {
  LinkState(std::size_t index, std::size_t capacity)
      : queue("queue " + std::to_string(index), capacity), input("input " + std::to_string(index), capacity) {}
  csp::Channel<Packet> queue;                // the sender writes, the relays read
  csp::Channel<Packet> input;                // the relays write, the receiver reads
  std::atomic<std::uint64_t> written{0};     // writes completed by the sender
  std::atomic<std::uint64_t> received{0};    // packets the receiver has read
  std::atomic<std::uint64_t> held_at_stall{0};  // writes completed when the sender found the link full
  std::atomic<bool> stalled{false};          // set once held_at_stall is
  nodes::PortReceiver* sender = nullptr;     // the relays' sender(), for a link that sends in place
};

// One case's runtime, relays and links; the tests spawn the processes.
class Harness {
 public:
  explicit Harness(const Case& c) : case_(c), runtime_(options(c)), relays_(c.threads, c.capacity, c.wake) {
    for (std::size_t i = 0; i < c.links.size(); ++i) {
      links_.push_back(std::make_unique<LinkState>(i, c.capacity));
      relays_.add(c.links[i].from, c.links[i].to, links_[i]->queue.reader(), links_[i]->input.writer());
    }
    for (std::size_t i = 0; i < c.links.size(); ++i)
      if (c.links[i].in_place) links_[i]->sender = &relays_.sender(i);
  }

  csp::Runtime& runtime() { return runtime_; }
  LinkState& link(std::size_t i) { return *links_[i]; }
  bool shut_down() const { return shut_down_.load(std::memory_order_acquire); }

  // What the network's shutdown does to relayed links; safe from any thread.
  void shutdown() {
    shut_down_.store(true, std::memory_order_release);
    relays_.poison();
    for (auto& l : links_) {
      l->queue.poison();
      l->input.poison();
    }
  }

  // Spawns the relays and runs every process to its end, within the
  // watchdog's limit; the error that ended the run, or "" if none did.
  std::string run(const std::string& what) {
    relays_.spawn(runtime_);
    test::Watchdog dog(run_limit, [this] { shutdown(); }, what);
    std::string error;
    try {
      runtime_.run();
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (dog.fired())
      error = "no end within " + std::to_string(run_limit.count()) + " ms" + (error.empty() ? "" : "; then " + error);
    return error;
  }

  nodes::RelayCounters totals() const {
    nodes::RelayCounters sum;
    for (unsigned t = 0; t < case_.threads; ++t) sum += relays_.counters(t);
    return sum;
  }

 private:
  static csp::RuntimeOptions options(const Case& c) {
    csp::RuntimeOptions o;
    o.threads = c.threads;
    o.shared_cores = c.shared_cores;
    return o;
  }

  const Case& case_;
  csp::Runtime runtime_;
  ThreadRelays relays_;
  std::vector<std::unique_ptr<LinkState>> links_;
  std::atomic<bool> shut_down_{false};
};

std::uint64_t pacer_seed(std::uint64_t seed, std::size_t link, int end) { return mix(seed * 131 + link * 2 + end); }

// Throws if link `l`'s sender has completed more writes than its buffers
// hold beyond what its receiver has read: the sender's count can only lag.
void check_held(const Case& c, std::size_t l, LinkState& link, std::uint64_t read) {
  const std::uint64_t written = link.written.load(std::memory_order_acquire);
  if (written > read + c.bound())
    throw std::logic_error("link " + std::to_string(l) + ": " + std::to_string(written - read) +
                           " packets held, more than 3K = " + std::to_string(c.bound()));
}

// Sends the link's packets from `first` on, pausing before each.
// A link that sends in place hands each packet to the relays' sender when
// it takes it at once, as a router's step would, and writes the rest.
void send_from(LinkState& link, std::size_t l, std::uint64_t first, std::uint64_t count, Pacer& pacer) {
  csp::Out<Packet> out = link.queue.writer();
  for (std::uint64_t id = first; id < count; ++id) {
    pacer.pause();
    Packet p = make_packet(l, id);
    if (link.sender && link.sender->takes_at_once(p)) {
      link.sender->take(p);
    } else {
      out.write(std::move(p));
    }
    link.written.fetch_add(1, std::memory_order_release);
  }
}

// Reads the link's packets from `first` on, checking each and the bound
// before each read; then that nothing more came.
void receive_from(const Case& c, LinkState& link, std::size_t l, std::uint64_t first, std::uint64_t count,
                  Pacer& pacer) {
  csp::In<Packet> in = link.input.reader();
  for (std::uint64_t id = first; id < count; ++id) {
    pacer.pause();
    check_held(c, l, link, id);
    check_packet(in.read(), l, id);
    link.received.store(id + 1, std::memory_order_release);
  }
  if (in.try_read()) throw std::logic_error("link " + std::to_string(l) + ": a packet more than was sent");
}

// Spawns the ordinary sender and receiver of every link but those marked
// in `skip`; the last receiver to finish shuts the relays down.
void spawn_transfers(Harness& h, const Case& c, std::uint64_t seed, std::atomic<std::size_t>& unfinished,
                     const std::vector<bool>& skip = {}) {
  for (std::size_t l = 0; l < c.links.size(); ++l) {
    if (l < skip.size() && skip[l]) continue;
    const LinkPlan& plan = c.links[l];
    h.runtime().spawn(
        "send " + std::to_string(l), plan.from,
        [&h, &plan, l, pacer = Pacer(plan.send, pacer_seed(seed, l, 0))]() mutable {
          send_from(h.link(l), l, 0, plan.packets, pacer);
        },
        plan.send_priority);
    h.runtime().spawn(
        "receive " + std::to_string(l), plan.to,
        [&h, &c, &plan, &unfinished, l, pacer = Pacer(plan.receive, pacer_seed(seed, l, 1))]() mutable {
          receive_from(c, h.link(l), l, 0, plan.packets, pacer);
          if (--unfinished == 0) h.shutdown();
        },
        plan.receive_priority);
  }
}

std::uint64_t total_packets(const Case& c) {
  std::uint64_t n = 0;
  for (const LinkPlan& l : c.links) n += l.packets;
  return n;
}

// All-to-all between 2 to 4 threads, one or two links each way per pair,
// K from 1 to 5, each end pausing at random, one receiver sleeping before
// every packet: every packet arrives once, in order and intact, no link
// holds more than 3K, the relays count each packet once each way, and the
// run ends.
TEST(ThreadRelays, RandomDelaysDeliverEveryPacketOnceInOrder) {
  const test::SeedRange seeds = test::seed_range(100);
  for (std::uint64_t seed = seeds.first; seed < seeds.first + seeds.count; ++seed) {
    const Case c = draw_case(seed, 4, 40);
    const std::string where = test::replay_line(seed, program) + ", " + describe(c);
    Harness h(c);
    std::atomic<std::size_t> unfinished{c.links.size()};
    spawn_transfers(h, c, seed, unfinished);
    const std::string error = h.run(where);
    ASSERT_EQ(error, "") << where;
    const nodes::RelayCounters totals = h.totals();
    ASSERT_EQ(totals.packets_sent, total_packets(c)) << where;
    ASSERT_EQ(totals.packets_received, total_packets(c)) << where;
  }
}

// The fewest packets a link whose receiver stalls takes in: 3K, less the
// credits the receiving relay may hold back while fewer than half of K are
// owed (the relays' flush), which it returns once the receiver reads.
std::uint64_t least_held(const Case& c) { return c.bound() - (c.capacity - 1) / 2; }

// A stalled link's sender: writes without waiting until the link takes no
// more (a few milliseconds without progress once least_held() are in, a
// second short of it), says how many it got in, then sends the rest.
void stall_then_send(Harness& h, const Case& c, std::size_t l, Pacer& pacer) {
  using namespace std::chrono_literals;
  LinkState& link = h.link(l);
  csp::Out<Packet> out = link.queue.writer();
  std::uint64_t id = 0;
  Packet next = make_packet(l, id);
  auto progress = Clock::now();
  for (;;) {
    if (id < c.links[l].packets && out.try_write(next)) {
      link.written.store(++id, std::memory_order_release);
      next = make_packet(l, id);
      progress = Clock::now();
      continue;
    }
    const Clock::duration patience = id >= least_held(c) ? Clock::duration(3ms) : Clock::duration(1s);
    if (Clock::now() - progress > patience) break;
    csp::sleep_for(20us);
  }
  link.held_at_stall.store(id, std::memory_order_relaxed);
  link.stalled.store(true, std::memory_order_release);
  send_from(link, l, id, c.links[l].packets, pacer);
}

// A stalled link's receiver: reads nothing until its sender has found the
// link full, checks how full, then reads everything.
void receive_after_stall(Harness& h, const Case& c, std::size_t l, Pacer& pacer) {
  LinkState& link = h.link(l);
  while (!link.stalled.load(std::memory_order_acquire)) csp::sleep_for(microseconds(50));
  const std::uint64_t held = link.held_at_stall.load(std::memory_order_relaxed);
  if (held < least_held(c) || held > c.bound())
    throw std::logic_error("link " + std::to_string(l) + ": a stalled receiver's link took " + std::to_string(held) +
                           " packets, not " + std::to_string(least_held(c)) + " to 3K = " +
                           std::to_string(c.bound()));
  receive_from(c, link, l, 0, c.links[l].packets, pacer);
}

// A stalled receiver: its link's sender, writing without waiting, gets at
// most 3K packets in (K in its queue, K on the relays' credits, K in the
// input), and at least 3K less the credits held back (least_held), while
// the other links flow past on the same relays and rings; once the
// receiver reads, everything arrives once and in order.
TEST(ThreadRelays, AStalledLinkHoldsNoMoreThanItsCredits) {
  const test::SeedRange seeds = test::seed_range(50);
  for (std::uint64_t seed = seeds.first; seed < seeds.first + seeds.count; ++seed) {
    Case c = draw_case(seed, 4, 24);
    std::mt19937_64 rng(mix(seed + 7));
    std::vector<bool> stalls(c.links.size(), false);
    stalls[rng() % c.links.size()] = true;
    for (std::size_t l = 0; l < c.links.size(); ++l) {
      if (rng() % 3 == 0) stalls[l] = true;
      if (stalls[l]) c.links[l].packets = c.bound() + 1 + rng() % (2 * c.bound());
    }
    const std::string where = test::replay_line(seed, program) + ", " + describe(c);
    Harness h(c);
    std::atomic<std::size_t> unfinished{c.links.size()};
    spawn_transfers(h, c, seed, unfinished, stalls);  // a stalled link's processes below instead
    for (std::size_t l = 0; l < c.links.size(); ++l) {
      if (!stalls[l]) continue;
      const LinkPlan& plan = c.links[l];
      h.runtime().spawn("stall " + std::to_string(l), plan.from,
                        [&h, &c, l, pacer = Pacer(plan.send, pacer_seed(seed, l, 0))]() mutable {
                          stall_then_send(h, c, l, pacer);
                        });
      h.runtime().spawn("stalled receive " + std::to_string(l), plan.to,
                        [&h, &c, &unfinished, l, pacer = Pacer(plan.receive, pacer_seed(seed, l, 1))]() mutable {
                          receive_after_stall(h, c, l, pacer);
                          if (--unfinished == 0) h.shutdown();
                        });
    }
    const std::string error = h.run(where);
    ASSERT_EQ(error, "") << where;
    ASSERT_EQ(h.totals().packets_received, total_packets(c)) << where;
  }
}

// Poison while packets are in flight (every sender sends until poisoned):
// from a process once the receivers have read a drawn number of packets,
// or from a thread outside the runtime after a drawn time. Every process
// ends, none with an exception, and what each link delivered before the
// end is a prefix of what was sent, in order and intact.
TEST(ThreadRelays, PoisonInFlightEndsEveryProcess) {
  const test::SeedRange seeds = test::seed_range(100);
  for (std::uint64_t seed = seeds.first; seed < seeds.first + seeds.count; ++seed) {
    const Case c = draw_case(seed, 1, 1);
    std::mt19937_64 rng(mix(seed + 11));
    const bool from_outside = rng() % 3 == 0;
    const std::uint64_t after_packets = rng() % (4 * c.bound() * c.links.size());
    const microseconds after_time(rng() % 2000);
    const std::string where = test::replay_line(seed, program) + ", " + describe(c) + ", poisoned " +
                              (from_outside ? "from outside after " + std::to_string(after_time.count()) + " us"
                                            : "after " + std::to_string(after_packets) + " packets");
    Harness h(c);
    std::atomic<std::uint64_t> delivered{0};
    for (std::size_t l = 0; l < c.links.size(); ++l) {
      const LinkPlan& plan = c.links[l];
      h.runtime().spawn(
          "send " + std::to_string(l), plan.from,
          [&h, l, pacer = Pacer(plan.send, pacer_seed(seed, l, 0))]() mutable {
            send_from(h.link(l), l, 0, UINT64_MAX, pacer);
          },
          plan.send_priority);
      h.runtime().spawn(
          "receive " + std::to_string(l), plan.to,
          [&h, &c, &delivered, l, pacer = Pacer(plan.receive, pacer_seed(seed, l, 1))]() mutable {
            LinkState& link = h.link(l);
            csp::In<Packet> in = link.input.reader();
            for (std::uint64_t id = 0;; ++id) {
              pacer.pause();
              check_held(c, l, link, id);
              check_packet(in.read(), l, id);
              link.received.store(id + 1, std::memory_order_release);
              delivered.fetch_add(1, std::memory_order_relaxed);
            }
          },
          plan.receive_priority);
    }
    if (!from_outside)
      h.runtime().spawn("poisoner", static_cast<unsigned>(rng() % c.threads), [&h, &delivered, after_packets] {
        while (delivered.load(std::memory_order_relaxed) < after_packets && !h.shut_down())
          csp::sleep_for(microseconds(20));
        h.shutdown();
      });
    // Poison from outside comes one channel at a time, and the deadlock
    // detector would take the moment when every live process waits on a
    // channel not yet poisoned for a deadlock; a process that sleeps until
    // the poisoning is done keeps a timer pending through it.
    std::atomic<bool> poisoned{false};
    std::thread outside;
    if (from_outside) {
      h.runtime().spawn("until poisoned", 0, [&poisoned] {
        while (!poisoned.load(std::memory_order_acquire)) csp::sleep_for(microseconds(50));
      });
      outside = std::thread([&h, &poisoned, after_time] {
        std::this_thread::sleep_for(after_time);
        h.shutdown();
        poisoned.store(true, std::memory_order_release);
      });
    }
    const std::string error = h.run(where);
    if (outside.joinable()) outside.join();
    ASSERT_EQ(error, "") << where;
    const nodes::RelayCounters totals = h.totals();
    ASSERT_LE(totals.packets_received, totals.packets_sent) << where;
  }
}

}  // namespace
