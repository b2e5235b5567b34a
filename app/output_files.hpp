// The files a command writes, removed again unless it finishes, so that a
// failed run leaves no output behind. A path is added just before it is
// written, and a failed command removes it even if the write that failed
// left an older file there, so that nothing at that path can pass for this
// command's output. Removal
// goes in reverse order, so a directory added before the files made in it
// goes last, once it is empty (a directory that is not empty stays).
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
  // Adds `path`, then writes it with write_to(path); returns the path.
  template <class Write>
  std::filesystem::path write(const std::filesystem::path& path, Write&& write_to) {
    add(path);
    write_to(path);
    return path;
  }
  // Adds `path`, then writes `text` to it whole (tracer/atomic_file.hpp);
  // std::runtime_error naming the path if it cannot be written.
  std::filesystem::path write_text(const std::filesystem::path& path, const std::string& text) {
    return write(path, [&](const std::filesystem::path& p) { tracer::write_text_atomically(p.string(), text); });
  }
  // The command finished: keep every file.
  void keep() { paths_.clear(); }

 private:
  std::vector<std::filesystem::path> paths_;
};

}  // namespace app
