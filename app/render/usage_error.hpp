// A bad command line, and the machine's option errors in the command line's
// terms. Every command's parser throws UsageError with a one-line message
// that names the option; main prints it with the command's usage hint.
#pragma once

#include <stdexcept>
#include <string>

#include <boost/program_options.hpp>

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

// The command line read against `options` (and `positional`), notified;
// Boost's errors become UsageError with Boost's one-line message.
boost::program_options::variables_map read_command_line(
    int argc, const char* const argv[], const boost::program_options::options_description& options,
    const boost::program_options::positional_options_description& positional = {});

}  // namespace app
