// Options as `vmpray` parses them from a command line, for the suites that
// test what a command line means without running the binary.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "app/render/options.hpp"

namespace test {

// The options of `vmpray ARGS...`; app::UsageError as the command would report.
inline app::Options parse(std::vector<const char*> args) {
  args.insert(args.begin(), "vmpray");
  return app::parse_options(static_cast<int>(args.size()), args.data());
}

// The same from one string of blank-separated words.
inline app::Options parse_words(const std::string& command_line) {
  std::istringstream in(command_line);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  std::vector<const char*> args;
  for (const std::string& word : words) args.push_back(word.c_str());
  return parse(std::move(args));
}

}  // namespace test
