// nodes::ThreadRelays: the links between routers that run on different
// runtime threads of one process, carried by one relay process per thread
// over lock-free single-producer rings, so that a packet crossing threads
// costs an enqueue and no wake-up of the other thread.
//
// Per link (one direction and buffer class, from a router on thread A to a
// router on thread B): a's router writes its output queue (a buffered
// channel of K packets, read by A's relay), A's relay moves packets into the
// ring A→B while it holds a credit for the link (K to start with), B's relay
// takes them from the ring when B's scheduler tells it they came
// (csp::Arrivals), stages them, and moves them into b's input channel with
// try_write as room appears, each move returning one credit to A's relay
// through the ring B→A. So a link holds at most K packets in a's output
// queue, K in the ring or staged, and K in b's input: a bounded FIFO from
// router to router, which is all a link between routers is.
//
// Why the network still cannot deadlock: the routers see a relayed link as
// any other (a bounded output queue that drains while the router at its
// far end reads its input). A relay blocks on nothing but its one ALT (the
// arrivals token, every outgoing queue it has credit for, room in every
// input it has staged packets for): it never writes with a blocking write,
// and a ring never fills (its capacity is the credits that can be out on
// it), so no link waits on another through a relay, and the channel
// dependencies are those of the unrelayed network. The deadlock detector
// sees packets in a ring as work (a pending csp::Arrivals).
//
// Batching: a relay that wakes (one select) takes everything ready (its
// rings, the queues it has credit for, room in the inputs it has staged
// packets for), lets the high-priority processes it made ready run and
// takes what they sent (a page request in, its reply out), then signals
// the threads it wrote to, once each; a busy thread notices the signal at
// its next switch.
//
// Orderly end: Network::shutdown() poisons the queues, the inputs and the
// relays' tokens; each relay then ends, as the routers do.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/packet.hpp"

namespace nodes {

// What one thread's relay carried; read after the run.
struct RelayCounters {
  std::uint64_t packets_sent = 0;      // packets this thread's relay put in rings
  std::uint64_t packets_received = 0;  // packets it took from rings
  std::uint64_t wakes = 0;             // times it woke to work
  std::uint64_t signals = 0;           // signals it gave other threads (batches sent)
};

class ThreadRelays {
 public:
  ThreadRelays(unsigned threads, std::size_t capacity);
  ~ThreadRelays();
  ThreadRelays(const ThreadRelays&) = delete;
  ThreadRelays& operator=(const ThreadRelays&) = delete;

  // Before spawn(): a link's output queue at its sending router (read by
  // the relay of from_thread) and its input at its receiving router
  // (written by the relay of to_thread); the threads differ.
  void add(unsigned from_thread, unsigned to_thread, csp::In<Packet> queue, csp::Out<Packet> into);
  std::size_t links() const;
  // One relay process per thread that has links; under a FifoScheduler only.
  void spawn(csp::Runtime& runtime);
  // Safe from any thread: poisons the relays' tokens (the network poisons
  // the queues and inputs).
  void poison();
  const RelayCounters& counters(unsigned thread) const { return counters_.at(thread); }

 private:
  struct Link;
  class Ring;
  class Relay;
  Ring& ring(unsigned from, unsigned to) { return *rings_[from * threads_ + to]; }

  const unsigned threads_;
  const std::size_t capacity_;
  std::vector<Link> links_;
  std::vector<std::unique_ptr<Ring>> rings_;  // [from * threads + to]
  std::vector<std::unique_ptr<csp::Arrivals>> arrivals_;  // per thread
  std::vector<csp::Channel<char>> tokens_;  // per thread: the handler's wake-up for its relay
  std::vector<RelayCounters> counters_;     // per thread, written by its relay
};

}  // namespace nodes
