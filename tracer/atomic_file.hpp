// Writing a file so that it is whole or not there at all: the bytes go to a
// fresh temporary file beside the target, which is renamed over the target
// only once every byte is out. A failed or interrupted write removes the
// temporary file and leaves whatever stood at the target untouched.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

namespace tracer {

// Runs write(file) on the temporary file; write returns false on failure.
// Throws std::runtime_error "PATH: what went wrong" if anything fails.
void write_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write);

void write_text_atomically(const std::string& path, std::string_view text);

}  // namespace tracer
