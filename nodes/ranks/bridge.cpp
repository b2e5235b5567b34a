// The bridge process: cut links over the transport, with credits; see bridge.hpp.
#include "nodes/ranks/bridge.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "nodes/ranks/bridge_wire.hpp"

namespace nodes {

namespace {

constexpr std::chrono::microseconds shortest_poll{1};
constexpr std::size_t poll_levels = 11;  // 1 us .. 1024 us
// A frame is posted once it holds this much: a message under the eager
// limit of MPI's shared-memory transport (4 KB in Open MPI) is delivered
// whole by the send; a larger one waits, after the receiver matches it,
// for the sender's next MPI call, which on a busy rank comes only after a
// run of pixels. A frame gathered because messages are dear (over TCP,
// whose eager limit in Open MPI is 64 KB) may hold more.
constexpr std::size_t frame_bytes = 3 * 1024;
constexpr std::size_t gathered_frame_bytes = 32 * 1024;
constexpr std::chrono::microseconds hot_window{1000};  // since the last activity
constexpr int reply_rounds = 8;  // yields to let what arrived answer before posting

}  // namespace

void FailureNote::set(int rank, std::string text) {
  std::lock_guard<std::mutex> lk(mutex_);
  if (set_.load(std::memory_order_relaxed)) return;
  rank_ = rank;
  text_ = std::move(text);
  set_.store(true, std::memory_order_release);
}

std::optional<std::pair<int, std::string>> FailureNote::get() const {
  std::lock_guard<std::mutex> lk(mutex_);
  if (!set_.load(std::memory_order_relaxed)) return std::nullopt;
  return std::make_pair(rank_, text_);
}

Bridge::Bridge(Transport& transport, const RankPlan& plan, Network& network, FailureNote& local_failure,
               FailureNote& remote_failure, BridgeCounters& counters)
    : transport_(transport),
      plan_(plan),
      network_(network),
      local_failure_(local_failure),
      remote_failure_(remote_failure),
      counters_(counters),
      capacity_(network.options().buffer_capacity),
      frames_(static_cast<std::size_t>(transport.size())),
      end_from_(static_cast<std::size_t>(transport.size()), false),
      ends_missing_(transport.size() - 1) {
  const CutEnds& cut = network.cut_ends();
  for (const auto& [link, queue] : cut.outgoing) {
    outgoing_by_link_[key(link)] = outgoing_.size();
    outgoing_.push_back(Outgoing{link, queue, plan.rank_of(link.to), capacity_, 0});
  }
  for (const auto& [link, into] : cut.incoming) {
    incoming_by_link_[key(link)] = incoming_.size();
    incoming_.push_back(Incoming{link, into, plan.rank_of(link.from), {}, 0, 0});
  }
  for (std::size_t i = 0; i < outgoing_.size(); ++i) {
    outgoing_[i].guard = alt_.add_input(outgoing_[i].queue);
    guard_owner_.emplace_back(true, i);
  }
  for (std::size_t i = 0; i < incoming_.size(); ++i) {
    incoming_[i].guard = alt_.add_room(incoming_[i].into);
    alt_.enable(incoming_[i].guard, false);
    guard_owner_.emplace_back(false, i);
  }
  for (std::size_t level = 0; level < poll_levels; ++level) {
    timeout_guards_.push_back(alt_.add_timeout(shortest_poll * (1 << level)));
    alt_.enable(timeout_guards_.back(), level == 0);
  }
}

std::uint64_t Bridge::key(const CutLink& link) const {
  return (std::uint64_t{link.from} * plan_.nodes() + link.to) * 256 + link.buffer_class;
}

WireWriter& Bridge::frame(int peer) { return frames_[static_cast<std::size_t>(peer)]; }

void Bridge::run() {
  try {
    carry();
  } catch (const csp::Poisoned&) {
    throw;
  } catch (const std::exception& e) {
    // Tell the peers before this process ends, or they would wait for it.
    local_failure_.set(transport_.rank(), std::string("process 'bridge' failed: ") + e.what());
    if (!stopping_) stop();
    drain();
    throw;
  }
}

void Bridge::carry() {
  for (;;) {
    if (!stopping_ && (network_.shut_down() || local_failure_.set_already())) stop();
    if (stopping_) return drain();
    bool active = receive_all();
    if (stopping_) continue;
    try {
      if (deliver_staged()) {
        active = true;
        pass_replies();
      }
    } catch (const csp::Poisoned&) {
      stop();
      continue;
    }
    // Poll at the shortest interval while an answer is due (packets sent
    // that have not come back as credits) or something happened lately;
    // back off once all is quiet, and then return every credit held back.
    const auto now = std::chrono::steady_clock::now();
    if (active) last_active_ = now;
    const bool hot = unacknowledged_ > 0 || now - last_active_ < hot_window;
    queue_credits(!hot);
    send_frames();
    transport_.progress();
    alt_.enable(timeout_guards_[level_], false);
    level_ = hot ? 0 : std::min(level_ + 1, poll_levels - 1);
    alt_.enable(timeout_guards_[level_], true);
    const std::size_t guard = alt_.select();
    if (guard >= guard_owner_.size()) continue;  // a timeout: poll the wire
    try {
      if (take(guard)) {
        gather();
        if (stopping_) continue;  // an `end` came over the wire meanwhile
        queue_credits(false);
        // Sent now rather than after the next select: the receiver may be idle.
        send_frames();
        transport_.progress();
        last_active_ = std::chrono::steady_clock::now();
      }
    } catch (const csp::Poisoned&) {
      stop();
    }
  }
}

// After a packet for the wire: the rest of this pass (the routers ready
// now may have more), then, where messages are dear and while the window
// lasts, every process ready on the thread, each in its turn, with what
// came over the wire meanwhile: the packets of a pass leave in one message
// per rank (take_outgoing posts a frame as it fills), and the message
// leaves at once when the thread has nothing else to run, so gathering
// adds no wait where a rank would idle.
void Bridge::gather() {
  const auto start = std::chrono::steady_clock::now();
  csp::yield();
  take_ready();
  if (!dear()) return;
  while (std::chrono::steady_clock::now() - start < gathering_.window && csp::yield_to_all()) {
    if (receive_all()) {
      if (stopping_) return;
      deliver_staged();
    }
    take_ready();
  }
}

// Where messages are dear, what was just delivered runs before the bridge
// posts: the high-priority processes it made ready (routers, page servers,
// and those they wake in turn), for a few rounds at most, and what they send
// is taken, so that a request's reply leaves now, with the credits it owes,
// and not a gathering window later. The pixel computers do not run first.
void Bridge::pass_replies() {
  if (!dear()) return;
  for (int round = 0; round < reply_rounds; ++round) {
    csp::yield();
    take_ready();
    if (!csp::yield_requested()) return;
  }
}

bool Bridge::dear() const {
  return gathering_.window.count() > 0 && post_cost_ >= static_cast<double>(gathering_.dear_message.count());
}

// What a ready guard offers: the packets of an outgoing link (true), or room
// in a local input, into which the staged packets go at once.
bool Bridge::take(std::size_t guard) {
  const auto [is_outgoing, index] = guard_owner_[guard];
  if (!is_outgoing) {
    deliver_staged();
    return false;
  }
  take_outgoing(outgoing_[index]);
  return true;
}

// Everything else ready after a wake, so that the packets of several links
// that became ready together leave in one message per rank, not one each.
void Bridge::take_ready() {
  while (const std::optional<std::size_t> guard = alt_.poll())
    if (*guard < guard_owner_.size()) take(*guard);
}

// Reads what the guard found and whatever else the link holds, while the
// credits last, into the frame for the link's rank.
void Bridge::take_outgoing(Outgoing& out) {
  WireWriter& w = frame(out.peer);
  std::optional<Packet> packet = out.queue.read();
  while (packet) {
    w.put(BridgeRecord::packet);
    put_link(w, out.link);
    put_packet(w, *packet);
    if (w.size() >= (dear() ? gathered_frame_bytes : frame_bytes)) post_frame(out.peer);
    ++counters_.packets_sent;
    ++unacknowledged_;
    counters_.bytes_sent += packet->bytes();
    if (--out.credits == 0) {
      alt_.enable(out.guard, false);
      break;
    }
    packet = out.queue.try_read();
  }
}

bool Bridge::receive_all() {
  bool any = false;
  for (;;) {
    ++counters_.polls;
    std::optional<nodes::Incoming> message = transport_.poll(Tag::bridge);
    if (!message) return any;
    any = true;
    receive(message->from, message->bytes);
  }
}

void Bridge::receive(int from, const Bytes& bytes) {
  WireReader r(bytes);
  while (!r.done()) {
    switch (static_cast<BridgeRecord>(r.get<std::uint8_t>())) {
      case BridgeRecord::packet: {
        const CutLink link = get_link(r);
        Packet packet = get_packet(r);
        if (stopping_) break;  // the network is gone; the machine's end means none should come
        const auto it = incoming_by_link_.find(key(link));
        if (it == incoming_by_link_.end())
          throw std::runtime_error("bridge: rank " + std::to_string(from) + " sent a packet on link " +
                                   std::to_string(link.from) + "->" + std::to_string(link.to) +
                                   ", which does not end on this rank");
        Incoming& in = incoming_[it->second];
        if (in.staged.size() >= capacity_)
          throw std::runtime_error("bridge: rank " + std::to_string(from) + " sent more packets on link " +
                                   std::to_string(link.from) + "->" + std::to_string(link.to) +
                                   " than it had credits for");
        ++counters_.packets_received;
        counters_.bytes_received += packet.payload.size();
        if (in.staged.empty()) {
          staged_.push_back(it->second);
          alt_.enable(in.guard, true);
        }
        in.staged.push_back(std::move(packet));
        break;
      }
      case BridgeRecord::credit: {
        const auto [link, count] = get_fields<CreditRecord>(r);
        if (stopping_) break;
        const auto it = outgoing_by_link_.find(key(link));
        if (it == outgoing_by_link_.end()) throw std::runtime_error("bridge: a credit for a link not cut here");
        Outgoing& out = outgoing_[it->second];
        if (out.credits + count > capacity_ || count > unacknowledged_)
          throw std::runtime_error("bridge: rank " + std::to_string(from) + " returned more credits than it owed");
        if (out.credits == 0) alt_.enable(out.guard, true);
        out.credits += count;
        unacknowledged_ -= count;
        break;
      }
      case BridgeRecord::end:
        if (end_from_[static_cast<std::size_t>(from)])
          throw std::runtime_error("bridge: rank " + std::to_string(from) + " ended twice");
        end_from_[static_cast<std::size_t>(from)] = true;
        --ends_missing_;
        if (!stopping_) stop();
        break;
      case BridgeRecord::abort: {
        auto abort = get_fields<AbortRecord>(r);
        remote_failure_.set(abort.rank, std::move(abort.text));
        if (!stopping_) stop();
        break;
      }
      default:
        throw std::runtime_error("bridge: rank " + std::to_string(from) + " sent an unknown record");
    }
  }
}

// Moves staged packets into their local inputs while there is room; each
// moved packet owes its sender a credit.
bool Bridge::deliver_staged() {
  bool any = false;
  for (std::size_t k = 0; k < staged_.size();) {
    Incoming& in = incoming_[staged_[k]];
    while (!in.staged.empty() && in.into.try_write(in.staged.front())) {
      in.staged.pop_front();
      if (in.credits_owed++ == 0) owing_.push_back(staged_[k]);
      any = true;
    }
    if (in.staged.empty()) {
      alt_.enable(in.guard, false);
      staged_[k] = staged_.back();
      staged_.pop_back();
    } else {
      ++k;
    }
  }
  return any;
}

// Credits ride with packets: a link's credits go into its rank's frame when
// that frame carries something anyway, alone a round of the bridge after
// half the link's buffer came to be owed, or (`all`) when the bridge goes
// quiet. The round lets the packets delivered run: a request delivered
// comes back as a reply, which the credits then ride with (on rings4 over
// TCP, two messages in five carried credits alone without the round). Held
// back, they cannot stall the sender: while fewer than half are owed, more
// than half of its credits are with it or with packets on their way here,
// and those, delivered, make the owed half; once half are owed, they wait
// one round at most, and a bridge that owes is active, so its rounds come
// at the shortest poll interval.
void Bridge::queue_credits(bool all) {
  const std::uint32_t batch = static_cast<std::uint32_t>((capacity_ + 1) / 2);
  std::size_t kept = 0;
  for (std::size_t i : owing_) {
    Incoming& in = incoming_[i];
    WireWriter& w = frame(in.peer);
    if (!all && w.size() == 0 && (in.credits_owed < batch || !in.credits_waited)) {
      in.credits_waited = in.credits_owed >= batch;
      owing_[kept++] = i;
      continue;
    }
    w.put(BridgeRecord::credit);
    put_fields(w, CreditRecord{in.link, in.credits_owed});
    in.credits_owed = 0;
    in.credits_waited = false;
  }
  owing_.resize(kept);
}

void Bridge::post_frame(int peer) {
  WireWriter& w = frame(peer);
  ++counters_.messages_sent;
  counters_.wire_bytes_sent += w.size();
  const auto start = std::chrono::steady_clock::now();
  transport_.post(peer, Tag::bridge, w.take());
  const auto cost = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start);
  counters_.post_nanoseconds += static_cast<std::uint64_t>(cost.count());
  post_cost_ += (static_cast<double>(cost.count()) - post_cost_) / 32;
  w = WireWriter{};
}

void Bridge::send_frames() {
  for (int peer = 0; peer < transport_.size(); ++peer)
    if (frame(peer).size() > 0) post_frame(peer);
}

void Bridge::stop() {
  stopping_ = true;
  network_.shutdown();
  const auto failure = local_failure_.get();
  for (int peer = 0; peer < transport_.size(); ++peer) {
    if (peer == transport_.rank()) continue;
    WireWriter& w = frame(peer);
    if (failure) {
      w.put(BridgeRecord::abort);
      put_fields(w, AbortRecord{failure->first, failure->second});
    }
    w.put(BridgeRecord::end);
  }
  send_frames();
}

// After stop(): until every peer has said `end` and every send is complete.
void Bridge::drain() {
  auto nap = shortest_poll;
  while (ends_missing_ > 0 || transport_.pending() > 0) {
    const bool any = receive_all();
    send_frames();
    transport_.progress();
    if (any) continue;
    csp::sleep_for(nap);
    nap = std::min<std::chrono::microseconds>(nap * 2, shortest_poll * (1 << (poll_levels - 1)));
  }
}

}  // namespace nodes
