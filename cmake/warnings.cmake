# vmpray::warnings: the warning flags every target of the project links.
add_library(vmpray_warnings INTERFACE)
add_library(vmpray::warnings ALIAS vmpray_warnings)
target_compile_options(vmpray_warnings INTERFACE -Wall -Wextra -Wpedantic
  $<$<BOOL:${VMPRAY_WERROR}>:-Werror>)
