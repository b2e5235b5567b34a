// The manual page vmpray(1) and the bash completion script, made from the
// option descriptions --help prints (app/render/options.hpp's OptionGroup; the sweep's
// and the network study's), so neither can drift from what the parser
// takes; `vmpray --manpage` and `vmpray --completion bash` (hidden) print
// them, and the build installs what they print (cmake/manual.cmake).
// Invariants: the page is man(7) roff that groff renders without warnings
// (every text taken from the descriptions escaped) and names every option
// of each command's --help, in its groups. The script needs bash alone: it
// registers _vmpray for `vmpray` and offers the command's options, the
// words of options with a fixed set of values, the subcommands and the
// built-in scenes, and file names otherwise (nothing after a number).
#pragma once

#include <string>

namespace app {

std::string manual_page();
std::string bash_completion();

}  // namespace app
