// Occam channels. Channel<T> owns the shared state and hands out its two ends,
// In<T> (reading) and Out<T> (writing), cheap copyable handles; one process reads, one writes.
// - Capacity 0 (the default) is a rendezvous: write() returns once a reader
//   has the value. Capacity k is a bounded buffer: a writer waits only while
//   k values are held, a reader only while none is. Values keep their order.
// - try_read() and try_write() never wait; read_for() waits at most a duration;
//   try_read_each() takes up to N values without waiting, under one lock.
// - A buffer's first slots come with its first value, unless made with
//   Slots::up_front, for where allocation must not fail: a write never does.
// - Poison, from either end, is permanent and wakes every waiter: every later
//   operation on either end throws Poisoned, even with values still buffered.
// - An unbound end (default-constructed or moved from) throws
//   std::logic_error on every operation; an ALT (alt.hpp) refuses it.
// - Waiting is for processes of a csp::Runtime (runtime.hpp); elsewhere a
//   read or write that would wait throws std::logic_error.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "csp/detail/wait.hpp"
#include "csp/errors.hpp"

namespace csp {

class Alt;
template <class T> class In;
template <class T> class Out;

namespace detail {

// The state of one channel. Protocol and invariants (all under the
// channel's spinlock):
// - capacity 0: a reader that finds a writer parked takes its value and
//   wakes it; otherwise it parks with an empty slot that the next writer
//   fills directly (so the writer returns without parking: the reader has
//   taken the value). A writer that finds only an ALT reader fires the ALT,
//   then parks until the ALT's read takes the value.
// - capacity k: the ring holds at most k values and grows on demand up to
//   k; a reader that frees a slot moves the first parked writer's value in
//   and wakes that writer.
// - An ALT may wait for room in a buffered channel (Alt::add_room): its
//   record waits in room_waiters_, and the reader that frees a slot (with no
//   parked writer to refill it) fires it. Poison fires it too.
// - ready_hint()/room_hint() mirror ready_locked()/room_locked() for
//   lock-free polling by an ALT: republished under the lock after every
//   change of the buffer or the parked writers, so they may be stale to
//   another thread; an ALT confirms a hint under the lock.
// - At most one of (parked readers, parked writers with data) is non-empty.
// - try_write on a rendezvous channel succeeds only if a reader is parked in
//   read(); a parked ALT would still have to run before taking the value.
// - A doorbell ALT (alt.hpp) watching a channel is rung, under the lock, when
//   a value is buffered or a writer parks (data_bell_), when a read frees a
//   slot that no parked writer refills (room_bell_), and by poison.
// Who wakes whom: writers wake readers (and fire ALTs), readers wake writers
// (and fire room guards), poison wakes all; see detail/wait.hpp for the
// claiming rules.
template <class T>
class ChannelState final : public ChannelBase {
 public:
  ChannelState(std::string name, std::size_t capacity, bool up_front)
      : ChannelBase(std::move(name), capacity) {
    if (up_front) ring_.resize(capacity);
    publish_hints(false, capacity > 0);
  }
  explicit ChannelState(Unbound u) : ChannelBase(u) {}

  bool ready_locked() const override {
    return poisoned() || count_ > 0 || !writers_.empty();
  }
  bool room_locked() const override { return poisoned() || count_ < capacity_; }

  T read() {
    ChannelLock lk(lock_);
    check_poison("In::read");
    if (count_ > 0) return pop_locked();
    if (std::optional<T> v = take_locked()) return std::move(*v);
    std::optional<T> slot;
    Waiter w;
    w.op = "reading";
    w.channel = this;
    Record rec;
    rec.waiter = &w;
    rec.slot = &slot;
    readers_.push_back(rec);
    finish_wait(park(w, lk.get()), rec, readers_);
    return std::move(*slot);
  }

  std::optional<T> try_read() {
    ChannelLock lk(lock_);
    check_poison("In::try_read");
    return take_locked();
  }

  // Up to `most` values without waiting, in order, under one lock: each is
  // handed to take(T&), which moves it out, and its slot then refilled from
  // the first parked writer. The room freed is rung once, at the end.
  template <class F>
  std::size_t try_read_each(std::size_t most, F&& take) {
    ChannelLock lk(lock_);
    check_poison("In::try_read_each");
    std::size_t n = 0;
    bool freed = false;
    for (; n < most; ++n) {
      if (count_ > 0) {
        take(*ring_[head_]);
        freed = drop_front_locked() || freed;
      } else if (Record* r = claim_front_locked(writers_)) {
        take(*static_cast<T*>(r->slot));
        complete(*r->waiter, WaitState::data, r->guard);
      } else {
        break;
      }
    }
    if (n == 0) return 0;
    publish_hints_locked();
    if (freed) announce_room_locked();
    return n;
  }

  std::optional<T> read_until(Clock::time_point deadline) {
    ChannelLock lk(lock_);
    check_poison("In::read_for");
    if (std::optional<T> v = take_locked()) return v;
    std::optional<T> slot;
    Waiter w;
    w.op = "reading";
    w.channel = this;
    Record rec;
    rec.waiter = &w;
    rec.slot = &slot;
    readers_.push_back(rec);
    park_until(w, lk.get(), deadline);
    lk.lock();
    const WaitState s = resolve_timeout(w);
    readers_.erase(rec);
    lk.unlock();
    if (s == WaitState::timed_out) return std::nullopt;
    if (s == WaitState::poisoned) throw Poisoned(name_);
    if (s == WaitState::refused) unwind_wait(w);
    return slot;
  }

  void write(T value) {
    ChannelLock lk(lock_);
    check_poison("Out::write");
    if (give_locked(value, false)) return;
    Waiter w;
    w.op = "writing";
    w.channel = this;
    Record rec;
    rec.waiter = &w;
    rec.slot = &value;
    writers_.push_back(rec);
    publish_hints_locked();
    data_bell_.ring();
    finish_wait(park(w, lk.get()), rec, writers_);
  }

  bool try_write(T& value) {
    ChannelLock lk(lock_);
    check_poison("Out::try_write");
    return give_locked(value, true);
  }

 private:
  void check_poison(const char* use) const {
    if (poisoned()) throw_poisoned(use);
  }

  // Lock held, count_ > 0: the buffer's first value, moved straight out
  // (the value a read returns); refills the slot from the first parked
  // writer, or rings for the room it frees.
  T pop_locked() {
    T v(std::move(*ring_[head_]));
    const bool freed = drop_front_locked();
    publish_hints_locked();
    if (freed) announce_room_locked();
    return v;
  }

  // Lock held, count_ > 0, the first value moved out: frees its slot and
  // refills the buffer from the first parked writer. Returns whether room
  // was left (no writer was parked), which the caller announces once its
  // hints are published.
  bool drop_front_locked() {
    ring_[head_].reset();
    if (++head_ == ring_.size()) head_ = 0;
    --count_;
    Record* r = claim_front_locked(writers_);
    if (!r) return true;
    push_locked(std::move(*static_cast<T*>(r->slot)));
    complete(*r->waiter, WaitState::data, r->guard);
    return false;
  }

  // Lock held: room was freed; fires the first ALT waiting for room and
  // rings for processes that watch the room bell.
  void announce_room_locked() {
    if (Record* alt = claim_front_locked(room_waiters_)) complete(*alt->waiter, WaitState::data, alt->guard);
    room_bell_.ring();
  }

  // Lock held: a value without waiting (buffer first, then a parked writer).
  std::optional<T> take_locked() {
    if (count_ > 0) return std::optional<T>(pop_locked());
    if (Record* r = claim_front_locked(writers_)) {
      std::optional<T> v(std::move(*static_cast<T*>(r->slot)));
      complete(*r->waiter, WaitState::data, r->guard);
      publish_hints_locked();
      return v;
    }
    return std::nullopt;
  }

  // Lock held: hands value to a parked reader or the buffer. Fires a parked
  // ALT reader. Returns false if the writer must park (value untouched).
  bool give_locked(T& value, bool only_if_taken) {
    if (only_if_taken && capacity_ == 0) {
      while (Record* r = readers_.front()) {
        if (!r->slot) return false;  // an ALT would have to run before taking it
        readers_.erase(*r);
        if (try_claim(*r->waiter)) return deliver(*r, value);
      }
      return false;
    }
    if (Record* r = claim_front_locked(readers_)) {
      if (r->slot) return deliver(*r, value);
      complete(*r->waiter, WaitState::data, r->guard);
    }
    if (count_ == capacity_) return false;
    push_locked(std::move(value));
    data_bell_.ring();
    return true;
  }

  bool deliver(Record& r, T& value) {
    static_cast<std::optional<T>*>(r.slot)->emplace(std::move(value));
    complete(*r.waiter, WaitState::data, r.guard);
    return true;
  }

  void push_locked(T&& value) {
    if (count_ == ring_.size()) grow_ring_locked();
    ring_[(head_ + count_) % ring_.size()].emplace(std::move(value));
    ++count_;
    publish_hints_locked();
  }

  // The hints ready_hint()/room_hint() read without the lock.
  void publish_hints_locked() { publish_hints(count_ > 0 || !writers_.empty(), count_ < capacity_); }

  // After park(): throws for poison, deadlock and a refused wait; data needs
  // nothing more.
  void finish_wait(WaitState s, Record& rec, RecordQueue& q) {
    if (s == WaitState::data) return;
    if (s == WaitState::poisoned) throw Poisoned(name_);
    ChannelLock lk(lock_);
    q.erase(rec);
    publish_hints_locked();
    lk.unlock();
    unwind_wait(*rec.waiter);
  }

  // The first slots on the first value, then room for twice the values, at
  // most capacity_ (a buffer allowed many values seldom holds them all: a
  // mailbox sized for every sender in a large machine, or the link queues
  // of a complete graph, most of which never carry a packet, would
  // otherwise take memory for all of them up front).
  void grow_ring_locked() {
    const std::size_t slots = ring_.empty() ? kFirstRingSlots : 2 * ring_.size();
    std::vector<std::optional<T>> bigger(std::min(capacity_, slots));
    for (std::size_t i = 0; i < count_; ++i) bigger[i] = std::move(ring_[(head_ + i) % ring_.size()]);
    ring_ = std::move(bigger);
    head_ = 0;
  }

  static constexpr std::size_t kFirstRingSlots = 4;
  // Values at head_ .. head_+count_ (modulo its size); none until the first
  // value is buffered, then grown on demand, by doubling, up to capacity_.
  std::vector<std::optional<T>> ring_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
};

// The channel of every unbound end of type T. It is poisoned from the
// start, so each operation of an unbound end stops at the poison check it
// makes anyway and only there, off the fast path, finds the channel unbound
// and throws std::logic_error instead of Poisoned; the ends' other members
// check first. It is never freed, and an end refers to it without a share
// in its ownership, so making an end unbound touches no reference count.
// It lives in static storage and its constructor allocates nothing, so
// making it cannot fail: a move of an end (noexcept) may be the first use.
template <class T>
std::shared_ptr<ChannelState<T>> unbound_channel() noexcept {
  alignas(ChannelState<T>) static unsigned char storage[sizeof(ChannelState<T>)];
  static ChannelState<T>* const channel = ::new (static_cast<void*>(storage)) ChannelState<T>(ChannelBase::Unbound{});
  return std::shared_ptr<ChannelState<T>>(std::shared_ptr<void>(), channel);
}

// What an In or an Out holds: its channel, or the unbound one when
// default-constructed or moved from.
template <class T>
class ChannelEnd {
 protected:
  ChannelEnd() : state_(unbound_channel<T>()) {}
  explicit ChannelEnd(std::shared_ptr<ChannelState<T>> s) : state_(std::move(s)) {}
  ChannelEnd(const ChannelEnd&) = default;
  ChannelEnd& operator=(const ChannelEnd&) = default;
  ChannelEnd(ChannelEnd&& o) noexcept : state_(std::exchange(o.state_, unbound_channel<T>())) {}
  ChannelEnd& operator=(ChannelEnd&& o) noexcept {
    state_ = std::exchange(o.state_, unbound_channel<T>());
    return *this;
  }
  ~ChannelEnd() = default;

  std::shared_ptr<ChannelState<T>> state_;
};

}  // namespace detail

// When a buffer's slots are allocated (see the top of this file).
enum class Slots { on_first_value, up_front };

// Example, a producer and a consumer (as csp::par processes):
//
//   csp::Channel<int> numbers("numbers");  // rendezvous
//   csp::par({[out = numbers.writer()]() mutable {
//               for (int i = 1; i <= 3; ++i) out.write(i);
//               out.poison();  // the end of the stream
//             },
//             [in = numbers.reader()]() mutable {
//               try {
//                 for (;;) std::cout << in.read() << '\n';  // 1, 2, 3
//               } catch (const csp::Poisoned&) {
//               }
//             }});
template <class T>
class Channel {
 public:
  explicit Channel(std::string name = {}, std::size_t capacity = 0, Slots slots = Slots::on_first_value)
      : state_(std::make_shared<detail::ChannelState<T>>(std::move(name), capacity, slots == Slots::up_front)) {}

  In<T> reader() const { return In<T>(state_); }
  Out<T> writer() const { return Out<T>(state_); }
  void poison() { state_->poison(); }
  const std::string& name() const { return state_->name(); }

 private:
  std::shared_ptr<detail::ChannelState<T>> state_;
};

template <class T>
class In : private detail::ChannelEnd<T> {
 public:
  In() = default;  // unbound: assign an end from a Channel before use; moving one leaves it unbound
  T read() { return state_->read(); }
  std::optional<T> try_read() { return state_->try_read(); }
  // Up to `most` values without waiting, each passed to take(T&) to be
  // moved out; returns how many. One lock for them all.
  template <class F>
  std::size_t try_read_each(std::size_t most, F&& take) {
    return state_->try_read_each(most, std::forward<F>(take));
  }
  std::optional<T> read_for(std::chrono::steady_clock::duration d) {
    return state_->read_until(detail::deadline_after(std::chrono::steady_clock::now(), d));
  }
  // Without the lock: true if a read would not wait (or the channel is
  // poisoned), as last published. Exact when the writer runs on the
  // caller's thread.
  bool ready_hint() const { return state_->ready_hint(); }
  bool poisoned() const {
    state_->require_bound("In::poisoned");
    return state_->poisoned();
  }
  void poison() {
    state_->require_bound("In::poison");
    state_->poison();
  }
  const std::string& name() const {
    state_->require_bound("In::name");
    return state_->name();
  }

 private:
  friend class Channel<T>;
  friend class Alt;
  explicit In(std::shared_ptr<detail::ChannelState<T>> s) : detail::ChannelEnd<T>(std::move(s)) {}
  using detail::ChannelEnd<T>::state_;
};

template <class T>
class Out : private detail::ChannelEnd<T> {
 public:
  Out() = default;  // unbound: assign an end from a Channel before use; moving one leaves it unbound
  void write(T value) { state_->write(std::move(value)); }
  bool try_write(T& value) { return state_->try_write(value); }
  // Without the lock: true if a write would not wait (or the channel is
  // poisoned), as last published. To a buffered channel's only writer a
  // true hint stays true until it writes: only the writer fills slots.
  bool room_hint() const { return state_->room_hint(); }
  bool poisoned() const {
    state_->require_bound("Out::poisoned");
    return state_->poisoned();
  }
  void poison() {
    state_->require_bound("Out::poison");
    state_->poison();
  }
  const std::string& name() const {
    state_->require_bound("Out::name");
    return state_->name();
  }

 private:
  friend class Channel<T>;
  friend class Alt;
  explicit Out(std::shared_ptr<detail::ChannelState<T>> s) : detail::ChannelEnd<T>(std::move(s)) {}
  using detail::ChannelEnd<T>::state_;
};

}  // namespace csp
