// Alt: selection over guards (see alt.hpp for the protocol).
#include "csp/alt.hpp"

#include <algorithm>
#include <bit>
#include <functional>
#include <stdexcept>
#include <string>

#include "csp/detail/process.hpp"

namespace csp {

using detail::Clock;
using detail::deadline_after;
using detail::WaitState;

Alt::Alt(Waiting waiting) {
  if (waiting == Waiting::doorbell) bell_ = std::make_unique<detail::Bell>("ALT bell");
}

Alt::~Alt() {
  if (!bell_) return;
  for (const Guard& g : guards_)
    if (on_channel(g.kind)) watch(g, {});
}

// Registers (or with an empty mark, unregisters) the bell and mark a
// channel guard's channel rings for this ALT.
void Alt::watch(const Guard& g, detail::BellMark mark) {
  detail::ChannelLock lk(g.channel->lock_);
  detail::BellMark& slot = g.kind == Kind::room ? g.channel->room_bell_ : g.channel->data_bell_;
  if (mark.bell && slot.bell == mark.bell)
    throw std::logic_error("Alt: '" + g.channel->name() + "' is guarded twice by one doorbell ALT, which takes a channel once");
  if (mark.bell && slot.bell)
    throw std::logic_error("Alt: '" + g.channel->name() + "' is already watched by another doorbell ALT");
  slot = mark;
}

// The guard is listed before its channel is told to ring the bell, and taken
// off again if that fails, so that the destructor, which unregisters every
// listed channel guard, leaves no channel ringing a bell that is gone (as a
// push_back that ran out of memory after the channel was told once did).
std::size_t Alt::add(Guard g) {
  if (on_channel(g.kind)) g.channel->require_bound(g.kind == Kind::room ? "Alt::add_room" : "Alt::add_input");
  if (g.kind == Kind::room && g.channel->capacity() == 0)
    throw std::logic_error("Alt::add_room: '" + g.channel->name() + "' is unbuffered");
  guards_.push_back(std::move(g));
  const std::size_t index = guards_.size() - 1;
  if (bell_ && on_channel(guards_.back().kind)) {
    try {
      watch(guards_.back(), bell_->mark(index));
    } catch (...) {
      guards_.pop_back();
      throw;
    }
  }
  dirty_ = true;
  return index;
}

void Alt::enable(std::size_t guard, bool on) {
  if (guard >= guards_.size()) {
    throw std::out_of_range("Alt::enable: no guard " + std::to_string(guard));
  }
  if (guards_[guard].enabled != on) dirty_ = true;
  guards_[guard].enabled = on;
}

std::size_t Alt::select() {
  const std::size_t chosen = select_from(favourite_);
  favourite_ = (chosen + 1) % guards_.size();
  return chosen;
}

std::size_t Alt::pri_select() { return select_from(0); }

std::optional<std::size_t> Alt::poll() {
  if (dirty_) prepare();
  std::size_t ready = none;
  if (bell_) {
    ready = poll_each(0);
  } else {
    ready = poll_hints(0);
    if (ready == none) {
      lock_channels();
      ready = poll_locked(0);
      unlock_channels();
    }
  }
  if (ready == none) return std::nullopt;
  return ready;
}

std::size_t Alt::select_from(std::size_t first) {
  if (dirty_) prepare();
  if (channels_.empty() && timeout_guard_ == none && !has_skip_) {
    throw std::logic_error("Alt::select: no guard is enabled, so it would wait forever (occam STOP)");
  }
  if (bell_) return select_by_bell(first);
  const std::size_t by_hint = poll_hints(first);
  if (by_hint != none) return by_hint;
  const Clock::time_point start = timeout_guard_ == none ? Clock::time_point() : Clock::now();
  lock_channels();
  const std::size_t ready = poll_locked(first);
  if (ready != none) {
    unlock_channels();
    return ready;
  }
  const Clock::time_point deadline =
      timeout_guard_ == none ? Clock::time_point::max() : deadline_after(start, guards_[timeout_guard_].after);
  return wait_locked(timeout_guard_, deadline);
}

// Derives from the enabled guards what every select needs: the distinct
// channels in address order (the locking order), the earliest timeout, SKIP.
// The address order of all input guards is sorted once, when guards change.
void Alt::prepare() {
  if (by_address_.size() != guards_.size()) sort_by_address();
  channels_.clear();
  timeout_guard_ = none;
  has_skip_ = false;
  if (bell_) {
    enabled_.assign((guards_.size() + 63) / 64, 0);
    always_.assign(enabled_.size(), 0);
    for (std::size_t i = 0; i < guards_.size(); ++i) {
      const Guard& g = guards_[i];
      if (!g.enabled) continue;
      const std::uint64_t bit = std::uint64_t{1} << (i % 64);
      if (on_channel(g.kind)) enabled_[i / 64] |= bit;
      if (always_ready(g)) always_[i / 64] |= bit;
    }
    for (std::size_t w = 0; w < enabled_.size(); ++w) bell_->arm(w, enabled_[w]);
  }
  for (std::size_t i : by_address_) {
    const Guard& g = guards_[i];
    if (!g.enabled) continue;
    if (on_channel(g.kind) && (channels_.empty() || channels_.back() != g.channel.get()))
      channels_.push_back(g.channel.get());
    if (g.kind == Kind::skip) has_skip_ = true;
    if (g.kind == Kind::timeout && (timeout_guard_ == none || g.after < guards_[timeout_guard_].after)) {
      timeout_guard_ = i;
    }
  }
  dirty_ = false;
}

void Alt::sort_by_address() {
  by_address_.resize(guards_.size());
  for (std::size_t i = 0; i < guards_.size(); ++i) by_address_[i] = i;
  std::stable_sort(by_address_.begin(), by_address_.end(), [this](std::size_t a, std::size_t b) {
    return std::less<>()(guards_[a].channel.get(), guards_[b].channel.get());
  });
}

// Lock-free first pass: the first channel guard whose hint says ready,
// confirmed under that channel's lock alone (a channel has one reader, and
// a room guard's channel one writer, so it stays ready until this ALT's owner
// acts on it). SKIP and timeouts are left to the locked poll. `none` sends
// the caller to the full locked path, which decides for certain.
std::size_t Alt::poll_hints(std::size_t first) const {
  if (has_skip_ || timeout_guard_ != none) return none;
  const std::size_t n = guards_.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (first + k) % n;
    const Guard& g = guards_[i];
    if (!g.enabled || !on_channel(g.kind) || !hinted(g)) continue;
    detail::ChannelLock lk(g.channel->lock_);
    return ready_locked(g) ? i : none;
  }
  return none;
}

std::size_t Alt::poll_locked(std::size_t first) const {
  const std::size_t n = guards_.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (first + k) % n;
    const Guard& g = guards_[i];
    if (!g.enabled) continue;
    const bool ready = always_ready(g) || (on_channel(g.kind) && ready_locked(g));
    if (ready) return i;
  }
  return none;
}

// Doorbell waiting: clear the bell, poll; if nothing is ready, wait for a
// ring (at once if one came during the poll) and start again.
std::size_t Alt::select_by_bell(std::size_t first) {
  const Clock::time_point deadline =
      timeout_guard_ == none ? Clock::time_point::max() : deadline_after(Clock::now(), guards_[timeout_guard_].after);
  for (;;) {
    bell_->clear();
    const std::size_t ready = poll_each(first);
    if (ready != none) return ready;
    detail::Waiter w;
    w.op = "in ALT over";
    w.channels = &channels_;
    const WaitState s = bell_->wait(w, deadline);
    if (s == WaitState::timed_out) return timeout_guard_;
    if (s == WaitState::aborted) detail::unwind_deadlock();
  }
}

// The first ready guard from guard `first` on, in rotation, among the
// enabled guards that are always ready (SKIP, an expired timeout) or whose
// channel rang the bell since it was last found not ready (see Bell): each
// such channel's mark is cleared, and its hint confirmed under its lock alone
// (a rendezvous channel's: a buffered one's needs no confirming).
std::size_t Alt::poll_each(std::size_t first) const {
  const std::size_t words = enabled_.size();
  const std::size_t first_word = first / 64;
  const std::uint64_t from_first = ~std::uint64_t{0} << (first % 64);
  // Word first_word twice: guards from `first` on, then, last, those before it.
  for (std::size_t k = 0; k <= words; ++k) {
    const std::size_t w = (first_word + k) % words;
    std::uint64_t candidates = (bell_->marks(w) & enabled_[w]) | always_[w];
    if (k == 0) candidates &= from_first;
    if (k == words) candidates &= ~from_first;
    for (; candidates; candidates &= candidates - 1) {
      const std::size_t i = w * 64 + static_cast<std::size_t>(std::countr_zero(candidates));
      const Guard& g = guards_[i];
      if (!on_channel(g.kind)) return i;
      bell_->clear_mark(i);
      if (!hinted(g)) continue;
      // A buffered channel's hint, once true, stays true until this ALT's
      // owner acts: only its one reader takes values (an input guard), only
      // its one writer fills slots (a room guard). No lock is needed to confirm.
      if (g.channel->capacity() > 0) {
        bell_->keep_mark(i);
        return i;
      }
      detail::ChannelLock lk(g.channel->lock_);
      if (ready_locked(g)) {
        bell_->keep_mark(i);
        return i;
      }
    }
  }
  return none;
}

// Channels locked; nothing ready. Links a record per enabled channel guard,
// parks once, then unlinks whatever the winner left behind.
std::size_t Alt::wait_locked(std::size_t timeout_guard, Clock::time_point deadline) {
  detail::Waiter w;
  w.op = "in ALT over";
  w.channels = &channels_;
  records_.clear();
  records_.reserve(guards_.size());
  for (std::size_t i = 0; i < guards_.size(); ++i) {
    if (guards_[i].enabled && on_channel(guards_[i].kind)) {
      records_.emplace_back();
      records_.back().waiter = &w;
      records_.back().guard = i;
    }
  }
  auto record = records_.begin();
  for (const Guard& g : guards_) {
    if (g.enabled && on_channel(g.kind)) queue_of(g).push_back(*record++);
  }

  // Armed under every lock, since a waker may claim w as soon as one is
  // released; then all but the last lock go, sleep() releases that one.
  const bool timed = timeout_guard != none;
  if (!detail::arm(w, timed)) {
    unlink_records();
    unlock_channels();
    detail::unwind_wait(w);
  }
  detail::Spinlock no_channel;
  detail::Spinlock& last = channels_.empty() ? no_channel : channels_.back()->lock_;
  if (channels_.empty()) no_channel.lock();
  for (std::size_t c = 0; c + 1 < channels_.size(); ++c) channels_[c]->lock_.unlock();
  detail::SpinlockLock lk(last, std::adopt_lock);
  WaitState s = WaitState::waiting;
  if (timed) {
    detail::sleep_until(w, lk, deadline);
  } else {
    s = detail::sleep(w, lk);
  }

  lock_channels();
  if (timed) s = detail::resolve_timeout(w);
  unlink_records();
  unlock_channels();
  if (s == WaitState::aborted) detail::unwind_deadlock();
  return s == WaitState::timed_out ? timeout_guard : w.fired;
}

// Channels locked: removes the records a waker has not already taken.
void Alt::unlink_records() {
  auto record = records_.begin();
  for (const Guard& g : guards_) {
    if (g.enabled && on_channel(g.kind)) queue_of(g).erase(*record++);
  }
}

// Ready without a channel: SKIP, and a timeout already expired.
bool Alt::always_ready(const Guard& g) {
  return g.kind == Kind::skip || (g.kind == Kind::timeout && g.after <= Clock::duration::zero());
}

// A channel guard's readiness: data (or poison) for an input, a free slot
// (or poison) for a room guard; hinted() without the lock, the other under it.
bool Alt::hinted(const Guard& g) {
  return g.kind == Kind::room ? g.channel->room_hint() : g.channel->ready_hint();
}

bool Alt::ready_locked(const Guard& g) {
  return g.kind == Kind::room ? g.channel->room_locked() : g.channel->ready_locked();
}

detail::RecordQueue& Alt::queue_of(const Guard& g) {
  return g.kind == Kind::room ? g.channel->room_waiters_ : g.channel->readers_;
}

void Alt::lock_channels() {
  for (detail::ChannelBase* c : channels_) c->lock_.lock();
}

void Alt::unlock_channels() {
  for (detail::ChannelBase* c : channels_) c->lock_.unlock();
  detail::flush_wakes();
}

}  // namespace csp
