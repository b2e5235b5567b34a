// Arguments of the benchmark programs: each number checked against its
// range before any work, so a mistake ends in a usage line and exit 2
// rather than an abort or a run grown to gigabytes (a negative count read
// as a huge unsigned one).
#pragma once

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

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

// main() of a benchmark: --help prints the usage; body(args) runs, and what
// it throws ends in one line on stderr: a bad argument (or an unknown scene,
// std::invalid_argument) with the usage and exit 2, any other error exit 1.
template <class Body>
int run_main(const char* program, const char* usage, int argc, char** argv, Body body) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && (args[0] == "-h" || args[0] == "--help")) {
    std::fputs(usage, stdout);
    return 0;
  }
  try {
    return body(args);
  } catch (const BadArgument& e) {
    std::fprintf(stderr, "%s: %s\n%s", program, e.what.c_str(), usage);
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s\n%s", program, e.what(), usage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 1;
  }
}

}  // namespace bench
