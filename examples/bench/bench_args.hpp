// Arguments of the benchmark programs: each number checked against its
// range before any work, so a mistake ends in a usage line and exit 2
// rather than an abort or a run grown to gigabytes (a negative count read
// as a huge unsigned one).
#pragma once

#include <charconv>
#include <string>

namespace bench {

// A bad argument: what() names it; the program prints its usage and exits 2.
struct BadArgument {
  std::string what;
};

// text as an integer in lo..hi, or BadArgument "NAME: expected lo..hi, got 'text'".
inline long parse_int(const std::string& text, long lo, long hi, const char* name) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi)
    throw BadArgument{std::string(name) + ": expected " + std::to_string(lo) + ".." + std::to_string(hi) +
                      ", got '" + text + "'"};
  return value;
}

}  // namespace bench
