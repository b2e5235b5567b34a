// nodes::Bridge: the one process per rank that carries the links a split
// machine cuts (network.hpp, rank_plan.hpp) over a Transport.
//
// Flow control, per direction and buffer class of a cut link (from a on
// this rank to b on rank q): the bridge takes a packet from a's output
// queue only while it holds a credit for that link; it starts with K
// credits (K = the network's buffer capacity). The bridge of rank q keeps
// arriving packets in a staging queue for the link and moves them into b's
// input channel with try_write as room appears; each packet moved owes
// one credit to a's rank, sent with the next frame to that rank, or alone
// once half the link's K are owed or the bridge goes quiet (queue_credits). So a cut link holds at most K packets in a's output
// queue, K in flight or staged, and K in b's input: a bounded FIFO from a's
// router to b's router, which is all a link between routers is.
//
// Why the network still cannot deadlock: the routers see a cut link exactly
// as a local one — a bounded output queue that drains while the router at
// its far end reads its input. The bridge blocks on nothing but its one
// ALT (over every outgoing queue it has credit for, room in every input it
// has staged packets for, and a timeout to poll the wire): it never writes
// with a blocking write and never waits inside the transport, so no link
// waits on another link through it. The channel dependency graph is that of
// the unsplit machine, acyclic by topology::next_hop's buffer classes.
//
// Polling: the transport moves and reports messages only when called. The
// bridge polls it after every wake-up, and every 4 us while an answer is
// due (a packet it sent has not come back as a credit) or within 1 ms of
// the last activity: an idle runtime thread watches for that short a
// timeout without sleeping, so a page request that crosses ranks costs
// tens of microseconds, not a sleep. Once all is quiet it waits twice as
// long each time, up to 1 ms, so a rank with nothing to do sleeps instead
// of spinning a core; any packet sent toward another rank wakes it at once.
// A wake lets the rest of the thread's ready pass run (csp::yield), then
// takes everything ready on every link (Alt::poll) before it sends, so the
// packets and credits of one pass reach a rank as one message.
//
// Orderly end: the machine's protocol ends with nothing in flight, and then
// rank 0 shuts its network down. A bridge that sees its network shut down,
// or receives `end` from a peer, shuts its network down (once), sends `end`
// to every peer, and then only drains: it ends when it has `end` from every
// peer (nothing more can come: the wire keeps each pair's order) and every
// send is complete. A failure on this rank (note_failure) first sends
// `abort` with its one line to every peer; a peer that receives it records
// it (remote_failure()) and ends the same way, so the failure ends the job.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "csp/csp.hpp"
#include "nodes/net/network.hpp"
#include "nodes/net/packet.hpp"
#include "nodes/ranks/rank_plan.hpp"
#include "nodes/ranks/transport.hpp"

namespace nodes {

// What one rank's bridge carried; read after the run.
struct BridgeCounters {
  std::uint64_t packets_sent = 0;      // packets that left this rank
  std::uint64_t bytes_sent = 0;        // their payload bytes (as the link counters count)
  std::uint64_t packets_received = 0;
  std::uint64_t bytes_received = 0;
  std::uint64_t messages_sent = 0;     // transport messages (packets and credits batched)
  std::uint64_t wire_bytes_sent = 0;   // their total size
  std::uint64_t polls = 0;             // times the bridge looked at the wire
};

// A failure of this rank, or of another one, as the one line to report.
class FailureNote {
 public:
  void set(int rank, std::string text);  // the first one stays
  std::optional<std::pair<int, std::string>> get() const;
  bool set_already() const { return set_.load(std::memory_order_acquire); }

 private:
  mutable std::mutex mutex_;
  std::atomic<bool> set_{false};
  int rank_ = 0;
  std::string text_;
};

class Bridge {
 public:
  Bridge(Transport& transport, const RankPlan& plan, Network& network, FailureNote& local_failure,
         FailureNote& remote_failure, BridgeCounters& counters);
  void run();

 private:
  struct Outgoing {
    CutLink link;
    csp::In<Packet> queue;
    int peer = 0;
    std::size_t credits = 0;
    std::size_t guard = 0;
  };
  struct Incoming {
    CutLink link;
    csp::Out<Packet> into;
    int peer = 0;
    std::deque<Packet> staged;
    std::uint32_t credits_owed = 0;
    std::size_t guard = 0;
  };

  void carry();
  bool receive_all();
  void receive(int from, const Bytes& frame);
  bool deliver_staged();
  bool take(std::size_t guard);
  void take_ready();
  void take_outgoing(Outgoing& out);
  void queue_credits(bool all);
  void post_frame(int peer);
  void send_frames();
  void stop();
  void drain();
  std::uint64_t key(const CutLink& link) const;
  WireWriter& frame(int peer);

  Transport& transport_;
  const RankPlan& plan_;
  Network& network_;
  FailureNote& local_failure_;
  FailureNote& remote_failure_;
  BridgeCounters& counters_;
  std::size_t capacity_;
  std::vector<Outgoing> outgoing_;
  std::vector<Incoming> incoming_;
  std::unordered_map<std::uint64_t, std::size_t> outgoing_by_link_, incoming_by_link_;
  std::vector<WireWriter> frames_;   // per peer rank: records to post this round
  std::vector<bool> end_from_;       // per peer rank
  int ends_missing_ = 0;
  bool stopping_ = false;
  csp::Alt alt_{csp::Alt::Waiting::doorbell};
  std::vector<std::pair<bool, std::size_t>> guard_owner_;  // per guard: (outgoing?, index); timeouts absent
  std::vector<std::size_t> staged_, owing_;  // incoming links with staged packets / credits owed
  std::size_t level_ = 0;                    // the timeout guard enabled
  std::uint64_t unacknowledged_ = 0;         // packets sent whose credits have not come back
  std::chrono::steady_clock::time_point last_active_{};
  std::vector<std::size_t> timeout_guards_;  // 4 us, 8 us, ... 1 ms
};

}  // namespace nodes
