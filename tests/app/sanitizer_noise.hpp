// Removes AddressSanitizer's expected fiber-stack warning from a captured
// stderr. Debian's Boost.Context does not announce stack switches to ASan,
// so a C++ exception thrown on a fiber stack makes ASan print a warning
// ("ASan is ignoring requested __asan_handle_no_return ...") followed by two
// lines of explanation. That is not output of vmpray; everything else is kept.
#pragma once

#include <sstream>
#include <string>

inline std::string without_sanitizer_noise(const std::string& captured) {
  std::istringstream in(captured);
  std::string kept, line;
  while (std::getline(in, line)) {
    const bool noise = (line.rfind("==", 0) == 0 && line.find("WARNING: ASan") != std::string::npos) ||
                       line == "False positive error reports may follow" ||
                       line.rfind("For details see https://github.com/google/sanitizers/issues/189", 0) == 0;
    if (!noise) kept += line + "\n";
  }
  return kept;
}
