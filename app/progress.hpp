// A one-line progress bar on stderr (work done/total, rate, ETA), redrawn at
// most a few times a second; disabled unless stderr is a terminal.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace app {

class ProgressBar {
 public:
  // unit: what is counted ("pixels"); enabled is usually stderr_is_terminal() && !quiet.
  ProgressBar(std::uint64_t total, std::string unit, bool enabled);
  void update(std::uint64_t done);
  void finish();  // clears the line

 private:
  using Clock = std::chrono::steady_clock;
  std::uint64_t total_;
  std::string unit_;
  bool enabled_;
  Clock::time_point start_, last_draw_;
};

bool stderr_is_terminal();

}  // namespace app
