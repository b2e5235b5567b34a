// Occam ALT: waits until one of several guards is ready and says which.
//
// Guards: channel inputs, a timeout (ready `after` from the start of each
// select), SKIP (always ready); each may be switched off with enable().
// select() is a fair ALT — polling starts at a rotating favourite, one past
// the last guard chosen, so among guards that stay ready each is chosen within
// guard_count() selects. pri_select() polls from guard 0: lowest index wins.
//
// Design (after Go's select): lock every enabled channel in address order,
// poll; if nothing is ready, link one waiter record on every enabled channel
// and park once. The first writer (or poison, or the timer) to claim the
// waiter wins; on wake-up the ALT relocks its channels and unlinks the losing
// records. After select() returns i for an input guard, the caller reads that
// input: since a channel has a single reader, the read does not block.
// A poisoned input counts as ready; its read throws Poisoned.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <vector>

#include "csp/channel.hpp"

namespace csp {

class Alt {
 public:
  template <class T>
  std::size_t add_input(In<T> in) {
    return add(Guard{Kind::input, std::move(in.state_), {}, true});
  }
  std::size_t add_timeout(std::chrono::steady_clock::duration after) {
    return add(Guard{Kind::timeout, nullptr, after, true});
  }
  std::size_t add_skip() { return add(Guard{Kind::skip, nullptr, {}, true}); }
  void enable(std::size_t guard, bool on);
  std::size_t guard_count() const { return guards_.size(); }

  std::size_t select();
  std::size_t pri_select();

 private:
  enum class Kind { input, timeout, skip };
  struct Guard {
    Kind kind = Kind::input;
    std::shared_ptr<detail::ChannelBase> channel;  // input guards only
    std::chrono::steady_clock::duration after{};   // timeout guards only
    bool enabled = true;
  };

  std::size_t add(Guard g);
  std::size_t select_from(std::size_t first);
  void prepare();
  std::size_t poll_locked(std::size_t first) const;
  std::size_t wait_locked(std::size_t timeout_guard, detail::Clock::time_point deadline);
  void unlink_records();
  void lock_channels();
  void unlock_channels();

  static constexpr std::size_t none = static_cast<std::size_t>(-1);

  std::vector<Guard> guards_;
  std::size_t favourite_ = 0;
  // Derived from the enabled guards by prepare(), again only after a change.
  bool dirty_ = true;
  std::vector<detail::ChannelBase*> channels_;  // distinct, in address order
  std::size_t timeout_guard_ = none;            // earliest enabled timeout
  bool has_skip_ = false;
  std::vector<detail::Record> records_;         // scratch: one per enabled input
};

}  // namespace csp
