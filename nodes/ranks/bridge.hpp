// nodes::Bridge: the one process per rank that carries the links a split
// machine cuts (network.hpp, rank_plan.hpp) over a Transport, and its
// failure note. Its protocol is in docs/architecture.md, "Across processes".
//
// Invariants: per cut link and buffer class, at most K packets (K = the
// network's buffer capacity) in the sender's queue, K in flight or staged,
// and K in the receiver's input, held by credits; the bridge blocks on
// nothing but its one ALT and never waits inside the transport, so the
// channel dependency graph is the unsplit machine's and stays acyclic.
// Credits owed go with the next frame to their rank, a round after half of
// K are owed, or when the bridge goes quiet; where messages are dear, a wake
// gathers its thread's pass into one frame, and the replies to what arrived
// leave after one pass. Polling backs off from 1 us to 1 ms when all is
// quiet. At the end (its network shut down, or `end` from a peer) it sends
// `end`, after `abort` with a local failure's line, and drains till all end.
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
  std::uint64_t post_nanoseconds = 0;  // time spent handing messages to the transport
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
  // When a wake gathers the packets its thread sends before they leave
  // (docs/architecture.md, "Across processes"): while handing a message to
  // the transport costs at least `dear_message` on average (a socket's
  // system calls, not a copy into shared memory), for at most `window`.
  struct Gathering {
    std::chrono::microseconds window{20};    // zero: never
    std::chrono::nanoseconds dear_message{2000};  // zero: always
  };
  // Before run().
  void set_gathering(Gathering g) { gathering_ = g; }
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
    bool credits_waited = false;  // owed credits, due, waited a round for a packet to ride with
    std::size_t guard = 0;
  };

  void carry();
  bool receive_all();
  void receive(int from, const Bytes& frame);
  bool deliver_staged();
  bool take(std::size_t guard);
  void take_ready();
  void gather();
  void pass_replies();
  bool dear() const;  // messages cost enough to gather
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
  std::vector<std::size_t> timeout_guards_;  // 1 us, 2 us, ... 1 ms
  Gathering gathering_{};
  double post_cost_ = 0;  // nanoseconds a message takes to post, a running average
};

}  // namespace nodes
