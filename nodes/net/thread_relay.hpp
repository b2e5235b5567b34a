// nodes::ThreadRelays: the links between routers that run on different
// runtime threads of one process, carried by one relay process per thread
// over lock-free single-producer rings, so that a packet crossing threads
// costs an enqueue and no wake-up of the other thread (docs/architecture.md,
// "Why the network cannot deadlock", gives the protocol and its argument).
// A sending router's step may put a packet in the ring itself (sender()).
//
// Invariants: per link and buffer class, at most K packets in the sending
// router's queue, K in the ring or staged (the sending side's credits), and
// K in the receiving router's input; a ring never fills (its capacity is the
// credits that can be out on it); a relay blocks on nothing but its one ALT,
// so the channel dependencies are the unrelayed network's. A relay that
// wakes takes everything ready, lets what it made ready run, takes what that
// sent, and tells each thread it wrote to once (RelayWake). Packets in a
// ring are work to the deadlock detector. Network::shutdown() ends them.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/packet.hpp"

namespace nodes {

class PortReceiver;
class Router;

// What one thread's relay carried; read after the run. A cache line of
// its own: each relay counts every packet, and counters of two threads in
// one line would send it between their cores at every count.
struct alignas(64) RelayCounters {
  std::uint64_t packets_sent = 0;      // packets this thread's relay put in rings
  std::uint64_t packets_received = 0;  // packets it took from rings
  std::uint64_t wakes = 0;             // times it woke to work
  std::uint64_t signals = 0;           // signals it gave other threads (batches sent)
  std::uint64_t sent_in_place = 0;     // of packets_sent, put in by a router's step (sender())
  RelayCounters& operator+=(const RelayCounters& o);  // every count summed, as over a run's threads
};

// How a thread learns that a ring into it holds entries: its scheduler
// polls the rings' counters and the producers only wake it if it sleeps
// (csp::Arrivals::poke), or each batch marks it (csp::Arrivals::signal).
enum class RelayWake { poll, signal };

class ThreadRelays {
 public:
  ThreadRelays(unsigned threads, std::size_t capacity, RelayWake wake = RelayWake::poll);
  ~ThreadRelays();
  ThreadRelays(const ThreadRelays&) = delete;
  ThreadRelays& operator=(const ThreadRelays&) = delete;

  // Before spawn(): a link's output queue at its sending router (read by
  // the relay of from_thread) and its input at its receiving router
  // (written by the relay of to_thread); the threads differ.
  // Returns the link's index.
  std::size_t add(unsigned from_thread, unsigned to_thread, csp::In<Packet> queue, csp::Out<Packet> into);
  // Before spawn(): `into` of link `link` is input `input` of `router`, whose
  // step the receiving relay then takes in place when the router could
  // take the packet at once (router.hpp), rather than write it into `into`.
  void deliver_in_place(std::size_t link, Router& router, std::size_t input);
  // Before spawn(): what link `link`'s sending router may hand a packet to
  // in place of writing its queue (Router::send_across). It takes the
  // packet into the ring at once, signalling the far thread, when the queue
  // is empty and the link holds two credits or more; the last credit stays
  // with the relay, which so keeps the queue's guard enabled exactly while
  // credits are left. Used on the link's sending thread, while the relays run.
  PortReceiver& sender(std::size_t link);
  std::size_t links() const;
  // One relay process per thread that has links; under a FifoScheduler only.
  void spawn(csp::Runtime& runtime);
  // Safe from any thread: poisons the relays' tokens (the network poisons
  // the queues and inputs).
  void poison();
  const RelayCounters& counters(unsigned thread) const { return counters_.at(thread); }
  // The most credit entries of one link out on a ring at once, for links of
  // `capacity` packets.
  static std::size_t credit_entries(std::size_t capacity);
  // The bytes of one ring entry (a packet or credits); a packet that is not
  // of the usual shape (a route, or more than inline_payload bytes of
  // payload) takes a Packet on the heap besides while it is in the ring.
  static constexpr std::size_t ring_entry_bytes = 64;

 private:
  struct Link;
  class Ring;
  class Relay;
  class Sender;
  Ring& ring(unsigned from, unsigned to) { return *rings_[from * threads_ + to]; }

  // Thread `from` tells thread `to` that a ring into it holds entries, as
  // wake_ says, and counts it among from's signals.
  void tell(unsigned from, unsigned to) {
    ++counters_[from].signals;
    if (wake_ == RelayWake::poll) {
      arrivals_[to]->poke();
    } else {
      arrivals_[to]->signal();
    }
  }

  const unsigned threads_;
  const std::size_t capacity_;
  const RelayWake wake_;
  std::vector<Link> links_;
  std::vector<std::unique_ptr<Sender>> senders_;  // per link, made by sender()
  std::vector<std::unique_ptr<Ring>> rings_;  // [from * threads + to]
  std::vector<std::unique_ptr<csp::Arrivals>> arrivals_;  // per thread
  std::vector<csp::Channel<char>> tokens_;  // per thread: the handler's wake-up for its relay
  std::vector<RelayCounters> counters_;     // per thread, written by its relay
  // The relays spawned, kept until this ends: a link's Sender counts on its
  // relay's credits, and may be asked after the relay's process has ended
  // (a poisoned network's senders write on until they meet the poison).
  std::vector<std::shared_ptr<Relay>> spawned_;
};

}  // namespace nodes
