// A bad command line, and the machine's option errors in the command line's
// terms. Every command's parser throws UsageError with a one-line message
// that names the option; main prints it with the command's usage hint.
#pragma once

#include <stdexcept>
#include <string>

#include "nodes/machine/machine.hpp"

namespace app {

// A bad command line; the message is one line naming the option.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The machine's errors in the command line's terms. A MachineOptions field
// is named by its option ("cache_kb" -> "--cache-kb"; a field no option sets
// keeps its own name), and an OptionError becomes UsageError "OPTION: REASON".
std::string option_of_field(const std::string& field);
UsageError usage_error(const nodes::OptionError& error);

}  // namespace app
