// What a command shows on the terminal while it works: each phase on one
// line of stderr, redrawn at most a few times a second — a phase with no
// counts (reading the scene, building the database) by its name, the render
// as a bar (work done/total, rate, ETA) — and cleared once it ends. Shown
// only when stderr is a terminal and the command is not --quiet.
//
// The ETA is the work left at the recent rate (the last two seconds), not
// at the rate since the start: a render whose pixels grow slower as it
// reaches the costly part of the image would otherwise promise too little.
// An interrupt (SIGINT, SIGTERM) while a line is shown clears the line
// before the signal takes its course, so the shell's prompt starts clean.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

namespace app {

// Work done per second over the samples of the last `window` seconds.
class RecentRate {
 public:
  explicit RecentRate(double window_seconds = 2.0) : window_(window_seconds) {}
  // `done` items at `seconds` since the start; samples come in time order.
  void add(double seconds, std::uint64_t done);
  // 0 until the samples span some time.
  double per_second() const;

 private:
  double window_;
  std::deque<std::pair<double, std::uint64_t>> samples_;
};

// Seconds to finish `total` from `done` at `rate`'s pace; nullopt without a rate yet.
std::optional<double> eta_seconds(const RecentRate& rate, std::uint64_t done, std::uint64_t total);

class ProgressBar {
 public:
  // unit: what is counted ("pixels"); phase: what the line says it is doing;
  // enabled is usually stderr_is_terminal() && !quiet. Drawn at once, at 0,
  // unless `setup` names what comes first ("starting 16 processors"): then
  // the line says that until the first update(), where the bar and its
  // clock start, so the rate and the ETA count the work alone.
  ProgressBar(std::uint64_t total, std::string unit, bool enabled, std::string phase = "render", int fd = STDERR_FILENO,
              const std::string& setup = "");
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar();
  void update(std::uint64_t done);
  void finish();  // clears the line

 private:
  using Clock = std::chrono::steady_clock;
  void draw(std::uint64_t done, double elapsed);
  std::uint64_t total_;
  std::string unit_, phase_;
  bool enabled_;
  int fd_;
  Clock::time_point start_, last_draw_;
  double last_sample_ = 0;  // seconds since the start, of the rate's last sample
  RecentRate rate_;
  bool started_ = false;  // false while the setup line is shown
};

// A phase with no counts, named on the line while it lives ("reading
// teapot.nff"), cleared as it ends.
class PhaseNote {
 public:
  PhaseNote(const std::string& what, bool enabled, int fd = STDERR_FILENO);
  PhaseNote(const PhaseNote&) = delete;
  PhaseNote& operator=(const PhaseNote&) = delete;
  ~PhaseNote();

 private:
  bool enabled_;
  int fd_;
};

// work() run as a phase named `what` (PhaseNote); returns what it returns.
template <class Work>
auto in_phase(const std::string& what, bool enabled, Work&& work) {
  const PhaseNote note(what, enabled);
  return work();
}

bool stderr_is_terminal();

}  // namespace app
