// Progress bar drawing; see progress.hpp.
#include "app/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace app {

ProgressBar::ProgressBar(std::uint64_t total, std::string unit, bool enabled)
    : total_(total), unit_(std::move(unit)), enabled_(enabled), start_(Clock::now()),
      last_draw_(start_) {}

void ProgressBar::update(std::uint64_t done) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (done < total_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? double(done) / elapsed : 0.0;
  const double eta = rate > 0 ? double(total_ - done) / rate : 0.0;
  constexpr int kWidth = 30;
  const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
  std::fprintf(stderr, "\r[%.*s%*s] %llu/%llu %s, %.0f/s, ETA %.0f s ", filled,
               "##############################", kWidth - filled, "",
               static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_),
               unit_.c_str(), rate, eta);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (enabled_) std::fprintf(stderr, "\r%*s\r", 100, "");
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

}  // namespace app
