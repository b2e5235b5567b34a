// nodes::RouteRecorder: the network's part of a recorded run. Each router
// logs, for the packets the shared budget admits, its injection, every hop
// (leaving and arriving) and its delivery into its own node's RouteLog, and
// only counts, per kind with their hops, the packets delivered unrecorded.
//
// A RouteLog is written only by its node's router (on the node's thread),
// so no lock is taken; the budget is the only shared word, read relaxed and
// left alone once it reaches zero. Times are seconds since the run began:
// on the steady clock, or the router's virtual clock under virtual time.
// Who keeps the logs (one per node) is the layer above: the machine's
// Recorder adds its own events to each node's log (machine/recorder.hpp).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <vector>

#include "nodes/net/packet.hpp"

namespace nodes {

struct InjectEvent {
  std::uint64_t id = 0;
  double time = 0;
  NodeId destination = 0;
  std::uint32_t bytes = 0;  // payload
  std::uint8_t kind = 0;
};

// A packet leaving a router into a link queue (queue: the router's output
// queue index, port * classes + class) or arriving from a link (queue unused).
struct HopEvent {
  std::uint64_t id = 0;
  double time = 0;
  std::uint32_t queue = 0;
  std::uint16_t hop = 0;  // links crossed before this departure; after this arrival
};

struct DeliverEvent {
  std::uint64_t id = 0;
  double time = 0;
  std::uint16_t hops = 0;
};

struct RouteLog {
  std::vector<InjectEvent> injected;
  std::vector<HopEvent> departed, arrived;
  std::vector<DeliverEvent> delivered;
  std::array<std::uint64_t, 256> unrecorded{};  // delivered here without a record, by kind
  std::uint64_t unrecorded_hops = 0;
};

class RouteRecorder {
 public:
  RouteRecorder(std::uint64_t max_packets, bool virtual_time, std::chrono::steady_clock::time_point started);
  RouteRecorder(const RouteRecorder&) = delete;
  RouteRecorder& operator=(const RouteRecorder&) = delete;
  virtual ~RouteRecorder() = default;

  // The log of the node's router; asked once, when the router is made.
  virtual RouteLog& route_log(NodeId node) = 0;

  std::uint64_t max_packets() const { return max_packets_; }
  bool virtual_time() const { return virtual_time_; }
  // Seconds since the run began, for the calling process.
  double now() const;
  // Whether the packet being injected is recorded: true while the budget lasts.
  bool admit();
  // Whether the budget lasts: the recording window, which the layer above
  // also bounds its own events by.
  bool open() const { return left_.load(std::memory_order_relaxed) > 0; }

 private:
  std::uint64_t max_packets_;
  bool virtual_time_;
  std::chrono::steady_clock::time_point started_;
  std::atomic<std::uint64_t> left_;
};

}  // namespace nodes
