// The outputs of a command checked before it reads its scene: every file it
// will write must be one it can create, so that a path in a directory that
// is not there, or not writable, or a directory where a file should go, is
// refused at once instead of costing the render and then the image with it.
// A file is written to a temporary file beside it and renamed into place
// (tracer/atomic_file.hpp), so what matters is the directory it goes in;
// an existing target must be a regular file, since the rename would put a
// plain file in place of a device or FIFO.
// Errors are UsageError "OPTION: cannot write 'PATH': REASON", REASON the
// system's words for the directory that fails (strerror).
#pragma once

#include <filesystem>
#include <string>

#include "app/render/options.hpp"

namespace app {

// Why a file could not be written at `path`; empty when it can be.
std::string unwritable_file_reason(const std::filesystem::path& path);

// Why a directory could not be made or filled at `dir` (made, with its
// missing parents, if it is not there); empty when it can be.
std::string unwritable_directory_reason(const std::filesystem::path& dir);

// UsageError naming `option` if a file cannot be written at `path`.
void check_writable_file(const std::string& option, const std::filesystem::path& path);

// UsageError naming `option` if `dir` cannot be made or filled.
void check_writable_directory(const std::string& option, const std::filesystem::path& dir);

// Every file a render with these options writes: the image, --stats (unless
// "-", standard output), --tiles and the pictures.
void check_output_paths(const Options& options);

}  // namespace app
