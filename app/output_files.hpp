// The files a command writes, removed again unless it finishes, so that a
// failed run leaves no output behind. Every writer here puts a file in place
// whole or not at all (tracer/atomic_file.hpp), and a path is added only
// once its file is in place: a write that fails leaves whatever stood at
// that path before, and what a failed command removes is only what it wrote.
// Removal goes in reverse order, so a directory added before the files made
// in it goes last, once it is empty (a directory that is not empty stays).
#pragma once

#include <filesystem>
#include <functional>
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

}  // namespace app
