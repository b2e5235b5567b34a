// Output paths checked before the work; see output_check.hpp.
#include "app/experiments/output_check.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "app/experiments/machine_pictures.hpp"

namespace app {
namespace fs = std::filesystem;
namespace {

std::string shown(const fs::path& p) { return p.empty() ? std::string(".") : p.string(); }

// Why no file can be made in `dir`, which should exist; empty when one can.
std::string directory_refuses(const fs::path& dir) {
  const fs::path where = dir.empty() ? fs::path(".") : dir;
  std::error_code ec;
  const fs::file_status status = fs::status(where, ec);
  if (ec) return shown(dir) + ": " + ec.message();
  if (!fs::is_directory(status)) return shown(dir) + ": " + std::strerror(ENOTDIR);
  if (::access(where.c_str(), W_OK | X_OK) != 0) return shown(dir) + ": " + std::strerror(errno);
  return "";
}

}  // namespace

std::string unwritable_file_reason(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (fs::exists(status)) {
    const fs::file_status target = fs::status(path, ec);
    if (fs::is_directory(target)) return std::strerror(EISDIR);
    if (fs::exists(target) && !fs::is_regular_file(target))
      return "not a regular file (it would be replaced by one)";
  }
  return directory_refuses(path.parent_path());
}

std::string unwritable_directory_reason(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(fs::status(dir, ec))) return directory_refuses(dir);
  // Made with its parents: the nearest one there must take a new directory.
  fs::path parent = dir.parent_path();
  while (!parent.empty() && !fs::exists(fs::symlink_status(parent, ec))) parent = parent.parent_path();
  return directory_refuses(parent);
}

void check_writable_file(const std::string& option, const fs::path& path) {
  const std::string reason = unwritable_file_reason(path);
  if (!reason.empty()) throw UsageError(option + ": cannot write '" + path.string() + "': " + reason);
}

void check_writable_directory(const std::string& option, const fs::path& dir) {
  const std::string reason = unwritable_directory_reason(dir);
  if (!reason.empty()) throw UsageError(option + ": cannot write in '" + dir.string() + "': " + reason);
}

void check_output_paths(const Options& o) {
  check_writable_file("--output", o.output);
  if (!o.stats_path.empty() && o.stats_path != "-") check_writable_file("--stats", o.stats_path);
  if (!o.tiles_csv.empty()) check_writable_file("--tiles", o.tiles_csv);
  if (!o.replay_html.empty()) check_writable_file("--replay", o.replay_html);
  const PictureFiles pictures{o.pictures.machine_svg, o.pictures.ownership_png, o.pictures.report_html,
                              o.pictures.timeline_svg};
  // The page before its images, so that a bad --report is named as such.
  if (!o.pictures.report_html.empty()) check_writable_file("--report", o.pictures.report_html);
  for (const auto& [option, path] : picture_outputs(pictures)) check_writable_file(option, path);
}

}  // namespace app
