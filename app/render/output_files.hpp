// The files a command writes, removed again unless it finishes, so a failed
// run leaves no output behind. Every writer puts a file in place whole or
// not at all (tracer/atomic_file.hpp), and a path is added only once its
// file is in place, so what a failed command removes is only what it wrote;
// removal goes in reverse order, a directory after the files made in it.
// OutputPhase is a command writing its outputs: it holds back the signals
// that would end it half-way (SIGINT, SIGTERM, SIGHUP, SIGPIPE) and owns
// the OutputFiles written meanwhile; finish() checks the standard output
// and keeps the files unless a signal came; ending the phase removes the
// files not kept, then lets a held signal through, so the command still
// ends as asked, leaving nothing behind. For a single-threaded process
// only: other threads would take the signals.
#pragma once

#include <pthread.h>

#include <csignal>

#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "tracer/atomic_file.hpp"

namespace app {

class OutputFiles {
 public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles() {
    for (auto path = paths_.rbegin(); path != paths_.rend(); ++path) {
      std::error_code ignored;
      std::filesystem::remove(*path, ignored);
    }
  }

  void add(std::filesystem::path path) { paths_.push_back(std::move(path)); }
  // add() as a callable, for writers that report the files they make.
  std::function<void(const std::filesystem::path&)> tracker() {
    return [this](const std::filesystem::path& path) { add(path); };
  }
  // Writes `path` with write_to(path), which must put it in place whole or
  // not at all, then adds it; returns the path.
  template <class Write>
  std::filesystem::path write(const std::filesystem::path& path, Write&& write_to) {
    write_to(path);
    add(path);
    return path;
  }
  // Writes `text` to `path` whole, then adds it; std::runtime_error naming
  // the path if it cannot be written.
  std::filesystem::path write_text(const std::filesystem::path& path, const std::string& text) {
    return write(path, [&](const std::filesystem::path& p) { tracer::write_text_atomically(p.string(), text); });
  }
  // The command finished: keep every file.
  void keep() { paths_.clear(); }

 private:
  std::vector<std::filesystem::path> paths_;
};

class OutputPhase {
 public:
  OutputPhase() = default;
  OutputPhase(const OutputPhase&) = delete;
  OutputPhase& operator=(const OutputPhase&) = delete;

  // Where the command records what it writes.
  OutputFiles& files() { return files_; }

  // Whether a signal asked the command to stop while it wrote.
  bool interrupted() const {
    sigset_t pending;
    sigpending(&pending);
    for (int signal : held_signals)
      if (sigismember(&pending, signal)) return true;
    return false;
  }

  // Ends the writing once every output is in place: std::runtime_error
  // "standard output: cannot write the WHAT" if `out` cannot be flushed;
  // else the command's exit status, 1 if a signal came (its files go as the
  // phase ends), or 0 with every file kept.
  int finish(std::ostream& out, const std::string& what) {
    if (!out.flush()) throw std::runtime_error("standard output: cannot write the " + what);
    if (interrupted()) return 1;
    files_.keep();
    return 0;
  }

 private:
  static constexpr int held_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

  // Blocks the signals while it lives; restores the mask of before as it ends.
  class HeldSignals {
   public:
    HeldSignals() {
      sigset_t held;
      sigemptyset(&held);
      for (int signal : held_signals) sigaddset(&held, signal);
      pthread_sigmask(SIG_BLOCK, &held, &before_);
    }
    HeldSignals(const HeldSignals&) = delete;
    HeldSignals& operator=(const HeldSignals&) = delete;
    ~HeldSignals() { pthread_sigmask(SIG_SETMASK, &before_, nullptr); }

   private:
    sigset_t before_;
  };

  HeldSignals held_;   // first, so it ends last: a signal goes through once files_ is done
  OutputFiles files_;
};

}  // namespace app
