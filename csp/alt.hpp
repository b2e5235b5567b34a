// Occam ALT: waits until one of several guards is ready and says which.
// - Guards: a channel input (ready when a read would not block), room in a
//   buffered output (ready when a write would not block; for the channel's
//   only writer), a timeout (ready `after` from the start of each select, in
//   wall time even under virtual time; duration::max() never fires) and SKIP
//   (always ready). enable(i, on) switches guard i off and on.
// - select() is fair: polling starts one past the guard chosen last, so among
//   guards that stay ready each is chosen within guard_count() selects.
//   pri_select() polls from guard 0: the lowest ready index wins.
// - After select() returns an input guard the caller reads that input, which
//   does not block: a channel has a single reader. A poisoned channel counts
//   as ready, and the read or write then throws Poisoned.
// - Program errors throw std::logic_error: a select with no enabled guard
//   (occam STOP), an unbound end as a guard, a room guard on an unbuffered
//   channel, and a second guard on one channel in a doorbell ALT.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "csp/channel.hpp"

namespace csp {

// Example, a process that merges In<int>s a and b onto an Out<int> out and
// stops after a quiet spell:
//
//   csp::Alt alt;
//   const std::size_t left = alt.add_input(a), right = alt.add_input(b);
//   const std::size_t quiet = alt.add_timeout(std::chrono::milliseconds(10));
//   for (;;) {
//     const std::size_t i = alt.select();
//     if (i == left) out.write(a.read());
//     else if (i == right) out.write(b.read());
//     else if (i == quiet) break;  // 10 ms with neither ready
//   }
class Alt {
 public:
  // How a select that finds nothing ready waits.
  //
  // relink (after Go's select): lock every enabled channel in address order
  // and poll; if nothing is ready, link one waiter record on every enabled
  // channel and park once. The first writer (or poison, or the timer) to
  // claim the waiter wins; on wake-up the ALT relocks its channels and
  // unlinks the losing records. Before locking, a lock-free pass over the
  // channels' ready hints usually finds a ready guard at the cost of one lock.
  //
  // doorbell trades that linking for a bell: each channel guard registers
  // this ALT's bell, and its own mark bit in it, with its channel once, and
  // the channel rings it (detail/wait.hpp) when it may have become ready for
  // this ALT; a select polls only the guards whose channels rang since they
  // were last found not ready, and if none is ready parks on the bell alone,
  // then polls again. A park then costs one lock instead of two locks and a
  // record link per channel, a poll costs what rang rather than how many
  // guards there are, and the channels' other ends pay one bell ring per
  // write or freed slot. It suits a process that selects over many busy
  // channels and often finds none ready, such as a router. A channel has one
  // reader and one writer, so at most one doorbell ALT per end may watch it;
  // the ALT unregisters when destroyed.
  enum class Waiting { relink, doorbell };
  explicit Alt(Waiting waiting = Waiting::relink);
  ~Alt();
  Alt(const Alt&) = delete;
  Alt& operator=(const Alt&) = delete;

  template <class T>
  std::size_t add_input(In<T> in) {
    return add(Guard{Kind::input, std::move(in.state_), {}, true});
  }
  // For a buffered channel written only by this ALT's owner.
  template <class T>
  std::size_t add_room(Out<T> out) {
    return add(Guard{Kind::room, std::move(out.state_), {}, true});
  }
  std::size_t add_timeout(std::chrono::steady_clock::duration after) {
    return add(Guard{Kind::timeout, nullptr, after, true});
  }
  std::size_t add_skip() { return add(Guard{Kind::skip, nullptr, {}, true}); }
  void enable(std::size_t guard, bool on);
  std::size_t guard_count() const { return guards_.size(); }

  std::size_t select();
  std::size_t pri_select();
  // A PRI ALT with SKIP last, without a SKIP guard: the lowest ready guard,
  // or none if nothing is ready; never waits. A doorbell ALT polls only the
  // guards that rang, so a process that takes everything ready after a
  // select pays for what is ready, not for its guard count.
  std::optional<std::size_t> poll();

 private:
  enum class Kind { input, room, timeout, skip };
  static bool on_channel(Kind k) { return k == Kind::input || k == Kind::room; }
  struct Guard {
    Kind kind = Kind::input;
    std::shared_ptr<detail::ChannelBase> channel;  // input and room guards only
    std::chrono::steady_clock::duration after{};   // timeout guards only
    bool enabled = true;
  };

  std::size_t add(Guard g);
  std::size_t select_from(std::size_t first);
  std::size_t select_by_bell(std::size_t first);
  std::size_t poll_each(std::size_t first) const;
  void watch(const Guard& g, detail::BellMark mark);
  void prepare();
  void sort_by_address();
  std::size_t poll_hints(std::size_t first) const;
  std::size_t poll_locked(std::size_t first) const;
  std::size_t wait_locked(std::size_t timeout_guard, detail::Clock::time_point deadline);
  void unlink_records();
  static bool always_ready(const Guard& g);
  static bool hinted(const Guard& g);
  static bool ready_locked(const Guard& g);
  static detail::RecordQueue& queue_of(const Guard& g);
  void lock_channels();
  void unlock_channels();

  static constexpr std::size_t none = static_cast<std::size_t>(-1);

  std::vector<Guard> guards_;
  std::size_t favourite_ = 0;
  // Derived from the enabled guards by prepare(), again only after a change.
  bool dirty_ = true;
  std::vector<std::size_t> by_address_;         // all guards, by channel address
  std::vector<detail::ChannelBase*> channels_;  // enabled, distinct, in address order
  std::size_t timeout_guard_ = none;            // earliest enabled timeout
  bool has_skip_ = false;
  std::vector<detail::Record> records_;         // scratch: one per enabled input
  // Doorbell only, one bit per guard (64 to a word, as the bell's marks):
  std::vector<std::uint64_t> enabled_;  // enabled input and room guards
  std::vector<std::uint64_t> always_;   // enabled SKIP and expired timeouts
  std::unique_ptr<detail::Bell> bell_;          // doorbell waiting only
};

}  // namespace csp
