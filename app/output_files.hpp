// The files a command writes, removed again unless it finishes, so that a
// failed run leaves no output behind. A path is added before it is written:
// opening it for writing has already replaced whatever was there.
#pragma once

#include <filesystem>
#include <system_error>
#include <utility>
#include <vector>

namespace app {

class OutputFiles {
 public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles() {
    for (const auto& path : paths_) {
      std::error_code ignored;
      std::filesystem::remove(path, ignored);
    }
  }

  void add(std::filesystem::path path) { paths_.push_back(std::move(path)); }
  // The command finished: keep every file.
  void keep() { paths_.clear(); }

 private:
  std::vector<std::filesystem::path> paths_;
};

}  // namespace app
