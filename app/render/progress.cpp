// Progress lines; see progress.hpp.
#include "app/render/progress.hpp"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstring>

namespace app {
namespace {

// The line shown now, for the interrupt handler: its descriptor, -1 for none.
volatile std::sig_atomic_t shown_fd = -1;
constexpr int interrupts[] = {SIGINT, SIGTERM};
struct sigaction before[2];

void write_all(int fd, const char* text, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, text, size);
    if (n <= 0) return;
    text += n;
    size -= static_cast<std::size_t>(n);
  }
}

constexpr char clear_line[] = "\r\033[K";

// Clears the line, puts back the handler of before and lets the signal
// through to it (or to the default action, ending the process).
extern "C" void clear_then_pass_on(int signal) {
  if (shown_fd >= 0) write_all(shown_fd, clear_line, sizeof clear_line - 1);
  shown_fd = -1;
  for (int i = 0; i < 2; ++i)
    if (interrupts[i] == signal) sigaction(signal, &before[i], nullptr);
  std::raise(signal);
}

void show_line(int fd) {
  if (shown_fd >= 0) return;
  shown_fd = fd;
  struct sigaction action {};
  action.sa_handler = clear_then_pass_on;
  sigemptyset(&action.sa_mask);
  for (int i = 0; i < 2; ++i) sigaction(interrupts[i], &action, &before[i]);
}

void end_line(int fd) {
  if (shown_fd != fd) return;
  for (int i = 0; i < 2; ++i) sigaction(interrupts[i], &before[i], nullptr);
  shown_fd = -1;
  write_all(fd, clear_line, sizeof clear_line - 1);
}

}  // namespace

void RecentRate::add(double seconds, std::uint64_t done) {
  samples_.emplace_back(seconds, done);
  // Keep one sample at or before the window's start, so the span is the whole window.
  while (samples_.size() > 2 && samples_[1].first <= seconds - window_) samples_.pop_front();
}

double RecentRate::per_second() const {
  if (samples_.size() < 2) return 0.0;
  const auto& [t0, d0] = samples_.front();
  const auto& [t1, d1] = samples_.back();
  return t1 > t0 ? static_cast<double>(d1 - d0) / (t1 - t0) : 0.0;
}

std::optional<double> eta_seconds(const RecentRate& rate, std::uint64_t done, std::uint64_t total) {
  const double per_second = rate.per_second();
  if (!(per_second > 0)) return std::nullopt;
  return static_cast<double>(total > done ? total - done : 0) / per_second;
}

ProgressBar::ProgressBar(std::uint64_t total, std::string unit, bool enabled, std::string phase, int fd,
                         const std::string& setup)
    : total_(total),
      unit_(std::move(unit)),
      phase_(std::move(phase)),
      enabled_(enabled),
      fd_(fd),
      start_(Clock::now()),
      last_draw_(start_),
      started_(setup.empty()) {
  if (!enabled_) return;
  show_line(fd_);
  if (!started_) {
    const std::string line = "\r" + setup + "...\033[K";
    write_all(fd_, line.data(), line.size());
    return;
  }
  rate_.add(0, 0);
  draw(0, 0);
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(std::uint64_t done) {
  if (!enabled_) return;
  if (!started_) {  // the work begins: the bar replaces the setup line, its clock starts now
    started_ = true;
    start_ = last_draw_ = Clock::now();
    rate_.add(0, done);
    draw(done, 0);
    return;
  }
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // A sample each 50 ms is plenty for the rate, however often the work reports.
  if (elapsed - last_sample_ >= 0.05 || done == total_) {
    rate_.add(elapsed, done);
    last_sample_ = elapsed;
  }
  if (done < total_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  draw(done, elapsed);
}

void ProgressBar::draw(std::uint64_t done, double elapsed) {
  constexpr int kWidth = 30;
  const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
  const std::optional<double> eta = elapsed > 0.5 ? eta_seconds(rate_, done, total_) : std::nullopt;
  char eta_text[32] = "ETA --";
  if (eta) std::snprintf(eta_text, sizeof eta_text, "ETA %.0f s", *eta);
  char line[256];
  const int n = std::snprintf(line, sizeof line, "\r%s [%.*s%*s] %llu/%llu %s, %.0f/s, %s\033[K", phase_.c_str(),
                              filled, "##############################", kWidth - filled, "",
                              static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_),
                              unit_.c_str(), rate_.per_second(), eta_text);
  if (n > 0) write_all(fd_, line, std::min(static_cast<std::size_t>(n), sizeof line - 1));
}

void ProgressBar::finish() {
  if (!enabled_) return;
  enabled_ = false;
  end_line(fd_);
}

PhaseNote::PhaseNote(const std::string& what, bool enabled, int fd) : enabled_(enabled), fd_(fd) {
  if (!enabled_) return;
  show_line(fd_);
  const std::string line = "\r" + what + "...\033[K";
  write_all(fd_, line.data(), line.size());
}

PhaseNote::~PhaseNote() {
  if (enabled_) end_line(fd_);
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

}  // namespace app
