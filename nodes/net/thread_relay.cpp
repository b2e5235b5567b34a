// ThreadRelays: the rings, and the relay process of each thread.
#include "nodes/net/thread_relay.hpp"

#include "nodes/net/router.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace nodes {

struct ThreadRelays::Link {
  unsigned from_thread = 0;
  unsigned to_thread = 0;
  csp::In<Packet> queue;
  csp::Out<Packet> into;
  Router* router = nullptr;  // the router `into` feeds, when its step may be taken in place
  std::size_t input = 0;     // into's input number at that router

  // Delivers the packet (true) or leaves it untouched (false: no room).
  bool deliver(Packet& packet) {
    return (router && router->take_in_place(input, packet)) || into.try_write(packet);
  }
};

// One producer (the relay of the ring's first thread), one consumer (that
// of its second). An entry carries a packet for a link, or `credits` > 0
// returned for a link. Each count is written by one side only and sits on
// a cache line of its own; each side keeps its last view of the other's, so
// a push or a drain reads the other side's line only when the view says
// full or empty. The ring holds exactly the entries that can be out on it
// (a complete graph has millions of relayed links), and each side keeps
// its own slot index rather than a power-of-two mask.
// An entry is one cache line, written by the producer only and read by the
// consumer only, so a packet moves one line across. A packet of the usual
// shape (no route, a payload of up to inline_payload bytes: every message
// of the machine but a result) is packed into it field by field and made
// afresh on the far side, which allocates nothing; any other is moved to
// the heap and the entry carries the pointer.
class ThreadRelays::Ring {
 public:
  struct alignas(64) Entry {
    std::uint32_t link = 0;
    std::uint32_t credits = 0;
    NodeId source = 0;
    NodeId destination = 0;
    std::uint64_t id = 0;
    const std::byte* shared = nullptr;
    std::uint64_t shared_size = 0;
    std::byte payload[inline_payload] = {};  // or, when boxed, the Packet*
    std::uint16_t port = 0;
    std::uint16_t hops = 0;
    std::uint8_t kind = 0;
    std::uint8_t flags = 0;
    std::uint8_t payload_size = 0;
  };
  static_assert(sizeof(Entry) == ring_entry_bytes);
  // The fields put() and unpack() carry, in Packet's order: a field added
  // to Packet most likely makes the two sizes differ, whatever the ABI.
  struct Carried {
    NodeId source, destination;
    std::uint8_t kind;
    std::uint16_t port, hops;
    bool traced, recorded;
    std::uint64_t id;
    Payload payload;
    std::span<const std::byte> shared;
    std::vector<NodeId> route;
  };
  static_assert(sizeof(Packet) == sizeof(Carried), "a Packet field that put() and unpack() do not carry");
  static constexpr std::uint8_t traced = 1, recorded = 2, boxed = 4;

  explicit Ring(std::size_t capacity) : slots_(std::max<std::size_t>(capacity, 1)) {}

  // Room for `n` more entries. The credits bound what can be in a ring, so
  // a full ring is a broken invariant, never back-pressure.
  void reserve(std::size_t n) {
    if (tail_ - head_seen_ + n <= slots_.size()) return;
    head_seen_ = head_.load(std::memory_order_acquire);
    if (tail_ - head_seen_ + n > slots_.size()) throw std::logic_error("thread relay: ring full");
  }
  // After reserve(): a packet (left valid but unspecified), or credits;
  // unpublished until publish().
  void put(std::uint32_t link, Packet& packet) {
    if (packet.payload.size() > inline_payload || !packet.route.empty()) {
      // Boxed before the entry is claimed: an allocation that fails leaves
      // the ring as it was.
      auto* box = new Packet(std::move(packet));
      Entry& e = claim(link, 0);
      e.flags = boxed;
      std::memcpy(e.payload, &box, sizeof box);
      return;
    }
    Entry& e = claim(link, 0);
    e.source = packet.source;
    e.destination = packet.destination;
    e.id = packet.id;
    e.shared = packet.shared.data();
    e.shared_size = packet.shared.size();
    std::memcpy(e.payload, packet.payload.data(), packet.payload.size());
    e.port = packet.port;
    e.hops = packet.hops;
    e.kind = packet.kind;
    e.flags = static_cast<std::uint8_t>((packet.traced ? traced : 0) | (packet.recorded ? recorded : 0));
    e.payload_size = static_cast<std::uint8_t>(packet.payload.size());
  }
  void put_credits(std::uint32_t link, std::uint32_t credits) { claim(link, credits); }
  // The counters the consumer's scheduler polls (csp::Arrivals): entries
  // published, and taken.
  csp::Arrivals::Source source() const { return {&tail_published_, &head_}; }
  void publish() { tail_published_.store(tail_, std::memory_order_release); }

  // The packet an entry carries (credits == 0).
  static Packet unpack(const Entry& e) {
    if (e.flags & boxed) return std::move(*take_box(e));
    Packet p;
    p.source = e.source;
    p.destination = e.destination;
    p.kind = e.kind;
    p.port = e.port;
    p.hops = e.hops;
    p.traced = (e.flags & traced) != 0;
    p.recorded = (e.flags & recorded) != 0;
    p.id = e.id;
    p.payload.assign(e.payload, e.payload + e.payload_size);
    p.shared = {e.shared, static_cast<std::size_t>(e.shared_size)};
    return p;
  }

  // Takes every entry published so far; the head is published once. An
  // entry is taken once even if `take` throws (a poisoned network), for
  // taking a boxed packet frees it.
  template <class F>
  void drain(F&& take) {
    const std::uint64_t tail = tail_published_.load(std::memory_order_acquire);
    if (tail == head_local_) return;
    while (head_local_ != tail) {
      const Entry& e = slots_[head_slot_];
      head_slot_ = next(head_slot_);
      ++head_local_;
      take(e);
    }
    head_.store(head_local_, std::memory_order_release);
  }

  // Boxed packets still in the ring (a run that ended with packets in flight).
  ~Ring() {
    for (; head_local_ != tail_; ++head_local_) {
      const Entry& e = slots_[head_slot_];
      if (e.credits == 0 && (e.flags & boxed)) take_box(e);
      head_slot_ = next(head_slot_);
    }
  }

 private:
  // The heap packet of a boxed entry, owned by the caller from now on.
  static std::unique_ptr<Packet> take_box(const Entry& e) {
    Packet* box = nullptr;
    std::memcpy(&box, e.payload, sizeof box);
    return std::unique_ptr<Packet>(box);
  }
  std::size_t next(std::size_t slot) const { return slot + 1 == slots_.size() ? 0 : slot + 1; }
  // The entry at the tail, addressed to `link`; the tail moves past it.
  Entry& claim(std::uint32_t link, std::uint32_t credits) {
    Entry& e = slots_[tail_slot_];
    e.link = link;
    e.credits = credits;
    tail_slot_ = next(tail_slot_);
    ++tail_;
    return e;
  }

  std::vector<Entry> slots_;
  alignas(64) std::atomic<std::uint64_t> tail_published_{0};
  alignas(64) std::uint64_t tail_ = 0;  // the producer's
  std::uint64_t head_seen_ = 0;         // the producer's view of head_
  std::size_t tail_slot_ = 0;           // the producer's: tail_ modulo the slots
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::uint64_t head_local_ = 0;  // the consumer's
  std::size_t head_slot_ = 0;                 // the consumer's: head_local_ modulo the slots
};

// A relayed link's sending router's step in place, past the queue and the
// relay: the packet goes into the ring as the relay's send() would put it,
// under one of the link's credits, and the far thread is told at once
// (the relay tells once a batch; a router's step makes no batch). Taken
// only with the queue empty, so no packet of the link is overtaken, and
// with two credits or more, so the relay keeps the last one and its guard
// on the queue stays enabled exactly while credits are left. Both ends of
// the queue, the credits and the ring's producer side belong to the link's
// sending thread, where this runs.
class ThreadRelays::Sender final : public PortReceiver {
 public:
  Sender(ThreadRelays& relays, std::size_t link) : relays_(relays), link_(link) {}
  // By the sending thread's relay as it is made: its count of the link's credits.
  void bind(std::size_t* credits) { credits_ = credits; }
  bool takes_at_once(const Packet&) const override {
    return credits_ && *credits_ >= 2 && !relays_.links_[link_].queue.ready_hint();
  }
  void take(Packet& packet) override {
    Link& l = relays_.links_[link_];
    Ring& ring = relays_.ring(l.from_thread, l.to_thread);
    ring.reserve(1);
    ring.put(static_cast<std::uint32_t>(link_), packet);
    ring.publish();
    --*credits_;
    RelayCounters& counters = relays_.counters_[l.from_thread];
    ++counters.packets_sent;
    ++counters.sent_in_place;
    relays_.tell(l.from_thread, l.to_thread);
  }

 private:
  ThreadRelays& relays_;
  const std::size_t link_;
  std::size_t* credits_ = nullptr;  // null until spawn(): nothing is taken before
};

class ThreadRelays::Relay {
 public:
  Relay(ThreadRelays& relays, unsigned thread) : relays_(relays), thread_(thread) {
    for (std::size_t i = 0; i < relays_.links_.size(); ++i) {
      const Link& l = relays_.links_[i];
      if (l.from_thread == thread_) outgoing_.push_back(Outgoing{i, relays_.capacity_});
      if (l.to_thread == thread_) incoming_.push_back(Incoming{i});
    }
    out_index_.assign(relays_.links_.size(), none);
    in_index_.assign(relays_.links_.size(), none);
    for (std::size_t k = 0; k < outgoing_.size(); ++k) out_index_[outgoing_[k].link] = k;
    for (std::size_t k = 0; k < incoming_.size(); ++k) in_index_[incoming_[k].link] = k;
    touched_.assign(relays_.threads_, false);
    // outgoing_ is complete: its entries stay where they are from now on.
    for (Outgoing& o : outgoing_)
      if (o.link < relays_.senders_.size() && relays_.senders_[o.link]) relays_.senders_[o.link]->bind(&o.credits);
  }

  void run() {
    csp::Arrivals& arrivals = *relays_.arrivals_[thread_];
    std::vector<csp::Arrivals::Source> sources;  // none when the relays signal
    if (relays_.wake_ == RelayWake::poll)
      for (unsigned from = 0; from < relays_.threads_; ++from)
        if (from != thread_) sources.push_back(relays_.ring(from, thread_).source());
    if (!arrivals.attach(
            [token = relays_.tokens_[thread_].writer()]() mutable {
              char t = 0;
              try {
                (void)token.try_write(t);
              } catch (const csp::Poisoned&) {
                // The network is shutting down; the relay ends on its own.
              }
            },
            std::move(sources)))
      throw std::logic_error("thread relay: the runtime's scheduler takes no arrivals");
    struct Detach {
      csp::Arrivals& a;
      ~Detach() { a.detach(); }
    } detach{arrivals};
    build_alt();
    // Anything put in before the attach, and the credits for what of it
    // was delivered: nothing may wake this relay again for them.
    take_arrivals();
    flush();
    for (;;) {
      handle(alt_.select());
      take_ready();
      // The processes this wake made ready (the routers it delivered to, the
      // page servers behind them) run before the flush, and what they send
      // across goes in the same batch: a request that arrives here leaves
      // as a reply with the credits for it, under one signal. A relay is of
      // high priority, so the pixel computers of this thread wait for it.
      for (int round = 0; round < max_rounds && csp::yield_requested(); ++round) {
        csp::yield();
        take_ready();
      }
      flush();
    }
  }

 private:
  static constexpr std::size_t none = static_cast<std::size_t>(-1);
  static constexpr int max_rounds = 8;  // yields before a flush, while other high-priority work is ready
  // A link this thread sends on. Its credits are written on this thread
  // only (by the relay, and by the link's Sender), and kept here rather
  // than in the Link, which the far thread's relay reads: a count written
  // at every packet beside fields the other core reads would take their
  // cache line from it each time.
  struct Outgoing {
    std::size_t link;
    std::size_t credits;
    std::size_t guard = 0;  // enabled while credits are left
  };
  // Packets waiting for room in a link's input: at most K, in arrival
  // order from `head`. A vector, which takes no memory until a link first
  // stages (a deque takes half a kilobyte each, and most links never do).
  struct Staged {
    std::vector<Packet> packets;
    std::size_t head = 0;
    bool empty() const { return head == packets.size(); }
    Packet& front() { return packets[head]; }
    void push_back(Packet&& p) { packets.push_back(std::move(p)); }
    void pop_front() {
      if (++head == packets.size()) {
        packets.clear();
        head = 0;
      }
    }
  };
  struct Incoming {
    std::size_t link;
    Staged staged{};
    std::uint32_t owed = 0;  // credits to return
    std::size_t guard = 0;
  };

  // Guard 0: the token; then per outgoing link its queue (enabled while it
  // has credits), per incoming link room in its input (enabled while
  // packets are staged for it).
  void build_alt() {
    token_guard_ = alt_.add_input(relays_.tokens_[thread_].reader());
    for (Outgoing& o : outgoing_) o.guard = alt_.add_input(relays_.links_[o.link].queue);
    for (Incoming& i : incoming_) {
      i.guard = alt_.add_room(relays_.links_[i.link].into);
      alt_.enable(i.guard, false);
    }
    guard_owner_.assign(alt_.guard_count(), {false, none});
    for (std::size_t k = 0; k < outgoing_.size(); ++k) guard_owner_[outgoing_[k].guard] = {true, k};
    for (std::size_t k = 0; k < incoming_.size(); ++k) guard_owner_[incoming_[k].guard] = {false, k};
  }

  // One select per wake, then polls until nothing is ready: the doorbell
  // ALT polls only the guards that rang, and no guard is switched to do
  // so, so a wake costs what it moves and not the number of links.
  void take_ready() {
    while (const std::optional<std::size_t> g = alt_.poll()) handle(*g);
  }

  void handle(std::size_t guard) {
    if (guard == token_guard_) {
      (void)relays_.tokens_[thread_].reader().read();
      take_arrivals();
      return;
    }
    const auto [outgoing, k] = guard_owner_[guard];
    if (outgoing) {
      send(outgoing_[k]);
    } else {
      deliver(incoming_[k]);
    }
  }

  // Everything the rings into this thread hold.
  void take_arrivals() {
    relays_.arrivals_[thread_]->taking();
    ++relays_.counters_[thread_].wakes;
    for (unsigned from = 0; from < relays_.threads_; ++from) {
      if (from == thread_) continue;
      relays_.ring(from, thread_).drain([this](const Ring::Entry& e) {
        if (e.credits > 0) {
          Outgoing& o = outgoing_[out_index_[e.link]];
          if (o.credits == 0) alt_.enable(o.guard, true);
          o.credits += e.credits;
          return;
        }
        Incoming& i = incoming_[in_index_[e.link]];
        ++relays_.counters_[thread_].packets_received;
        Packet packet = Ring::unpack(e);
        if (i.staged.empty() && relays_.links_[i.link].deliver(packet)) {
          owe(i);
          return;
        }
        if (i.staged.empty()) alt_.enable(i.guard, true);
        i.staged.push_back(std::move(packet));
      });
    }
  }

  // Packets of one outgoing link, while it has credits and packets.
  void send(Outgoing& o) {
    Link& l = relays_.links_[o.link];
    Ring& ring = relays_.ring(thread_, l.to_thread);
    ring.reserve(o.credits);
    const auto link = static_cast<std::uint32_t>(o.link);
    const std::size_t n = l.queue.try_read_each(o.credits, [&](Packet& p) { ring.put(link, p); });
    if (n == 0) return;
    ring.publish();
    relays_.counters_[thread_].packets_sent += n;
    o.credits -= n;
    touched_[l.to_thread] = true;
    if (o.credits == 0) alt_.enable(o.guard, false);
  }

  // A credit owed for a packet delivered; a link that comes to owe half its
  // buffer is due to be paid at the next flush, which so visits only the
  // links it pays, however many links come into this thread.
  void owe(Incoming& i) {
    if (2 * ++i.owed >= relays_.capacity_ && 2 * (i.owed - 1) < relays_.capacity_)
      due_.push_back(static_cast<std::size_t>(&i - incoming_.data()));
  }

  // Staged packets of one incoming link, while its input has room.
  void deliver(Incoming& i) {
    Link& l = relays_.links_[i.link];
    while (!i.staged.empty() && l.deliver(i.staged.front())) {
      i.staged.pop_front();
      owe(i);
    }
    if (i.staged.empty()) alt_.enable(i.guard, false);
  }

  // Returns the credits owed, half a link's worth at least at a time, and
  // signals, once each, the threads written to. Holding back fewer than
  // half never stalls a link: a sender out of credits has K packets out,
  // and each is staged (so the input is full and drains as its router
  // reads) or delivered (owed), so the owed reach K/2 as the far end reads.
  void flush() {
    for (const std::size_t k : due_) {
      Incoming& i = incoming_[k];
      const Link& l = relays_.links_[i.link];
      Ring& ring = relays_.ring(thread_, l.from_thread);
      ring.reserve(1);
      ring.put_credits(static_cast<std::uint32_t>(i.link), i.owed);
      ring.publish();
      i.owed = 0;
      touched_[l.from_thread] = true;
    }
    due_.clear();
    for (unsigned t = 0; t < relays_.threads_; ++t) {
      if (!touched_[t]) continue;
      touched_[t] = false;
      relays_.tell(thread_, t);
    }
  }

  ThreadRelays& relays_;
  const unsigned thread_;
  std::vector<Outgoing> outgoing_;  // never resized after construction: Senders hold their credits' address
  std::vector<Incoming> incoming_;
  std::vector<std::size_t> out_index_, in_index_;  // per link: its place above, or none
  std::vector<std::pair<bool, std::size_t>> guard_owner_;  // per guard: (outgoing?, place)
  std::vector<bool> touched_;                      // per thread: written to since the last flush
  std::vector<std::size_t> due_;                   // incoming links owing half their buffer or more
  csp::Alt alt_{csp::Alt::Waiting::doorbell};
  std::size_t token_guard_ = 0;
};

RelayCounters& RelayCounters::operator+=(const RelayCounters& o) {
  packets_sent += o.packets_sent;
  packets_received += o.packets_received;
  wakes += o.wakes;
  signals += o.signals;
  sent_in_place += o.sent_in_place;
  return *this;
}

ThreadRelays::ThreadRelays(unsigned threads, std::size_t capacity, RelayWake wake)
    : threads_(threads), capacity_(capacity), wake_(wake), counters_(threads) {
  for (unsigned t = 0; t < threads_; ++t) {
    arrivals_.push_back(std::make_unique<csp::Arrivals>());
    // Written by the scheduler's arrivals callback, which must not allocate.
    tokens_.emplace_back("relay token " + std::to_string(t), 1, csp::Slots::up_front);
  }
}

ThreadRelays::~ThreadRelays() = default;

std::size_t ThreadRelays::links() const { return links_.size(); }

PortReceiver& ThreadRelays::sender(std::size_t link) {
  if (link >= links_.size()) throw std::out_of_range("thread relay: no link " + std::to_string(link));
  if (senders_.size() < links_.size()) senders_.resize(links_.size());
  if (!senders_[link]) senders_[link] = std::make_unique<Sender>(*this, link);
  return *senders_[link];
}

std::size_t ThreadRelays::add(unsigned from_thread, unsigned to_thread, csp::In<Packet> queue,
                              csp::Out<Packet> into) {
  if (from_thread == to_thread || from_thread >= threads_ || to_thread >= threads_)
    throw std::invalid_argument("thread relay: a relayed link joins two different threads of the runtime");
  links_.push_back(Link{from_thread, to_thread, std::move(queue), std::move(into)});
  return links_.size() - 1;
}

void ThreadRelays::deliver_in_place(std::size_t link, Router& router, std::size_t input) {
  Link& l = links_.at(link);
  l.router = &router;
  l.input = input;
}

// A ring from a to b carries the packets of links a→b (at most K each, by
// the credits) and the credits of links b→a: at most K out per link, and
// each entry at least half of K (flush), so at most two entries (one if K
// is 1).
std::size_t ThreadRelays::credit_entries(std::size_t capacity) { return capacity > 1 ? 2 : 1; }

void ThreadRelays::spawn(csp::Runtime& runtime) {
  std::vector<std::size_t> per_pair(std::size_t{threads_} * threads_, 0);
  std::vector<bool> has_links(threads_, false);
  for (const Link& l : links_) {
    per_pair[l.from_thread * threads_ + l.to_thread] += capacity_;
    per_pair[l.to_thread * threads_ + l.from_thread] += credit_entries(capacity_);
    has_links[l.from_thread] = has_links[l.to_thread] = true;
  }
  for (std::size_t p = 0; p < per_pair.size(); ++p) rings_.push_back(std::make_unique<Ring>(per_pair[p]));
  for (unsigned t = 0; t < threads_; ++t) {
    if (!has_links[t]) continue;
    auto relay = std::make_shared<Relay>(*this, t);
    spawned_.push_back(relay);
    runtime.spawn("thread relay " + std::to_string(t), t, [relay] { relay->run(); });
  }
}

void ThreadRelays::poison() {
  for (auto& t : tokens_) t.poison();
}

}  // namespace nodes
