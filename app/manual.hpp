// The manual page vmpray(1) and the bash completion script, made from the
// option descriptions --help prints (options.hpp's OptionGroup, the sweep's
// in sweep.hpp), so that neither can drift from what the parser takes. The
// hidden options `vmpray --manpage` and `vmpray --completion bash` print
// them; the build runs those and installs what they print
// (cmake/manual.cmake).
//
// Invariants: the page is man(7) roff that groff renders without warnings
// (every text taken from the descriptions is escaped: backslash, hyphen,
// quotes; a leading dot guarded) and names every option --help lists, in
// --help's groups, and every option of `vmpray sweep --help`. The script
// needs bash alone (not the bash-completion package): it defines _vmpray,
// registers it for `vmpray`, and offers for the word at the cursor the
// options of the command (the render's or the sweep's), the words an option
// with a fixed set of values takes, the subcommand and the built-in scenes,
// and file names otherwise (nothing after an option that takes a number).
#pragma once

#include <string>

namespace app {

std::string manual_page();
std::string bash_completion();

}  // namespace app
