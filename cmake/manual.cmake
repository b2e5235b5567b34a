# The manual page vmpray(1) and the bash completion script, printed by the
# built program itself (`vmpray --manpage`, `vmpray --completion bash`;
# app/manual.hpp) from the option descriptions --help prints, so that both
# describe the options that very binary parses.
# Invariants: after every link of the program, DIRECTORY holds vmpray.1 and
# vmpray.bash-completion from that binary, each written whole (under a
# temporary name, then renamed) or not at all: a failed run fails the build
# and leaves no file half written. A cross build runs the program through
# CMAKE_CROSSCOMPILING_EMULATOR, and makes and installs neither file when it
# has none.
#
# Two uses of this one file:
#   include(cmake/manual.cmake) defines
#     vmpray_add_manual(TARGET DIRECTORY dir)
#   which prints both files after TARGET links and installs them: the page
#   in MANDIR/man1, the script where bash-completion looks for it
#   (DATADIR/bash-completion/completions/vmpray). Needs GNUInstallDirs.
#   cmake -DPROGRAM=... -DDIRECTORY=... [-DEMULATOR=...] -P cmake/manual.cmake
#   writes both files from PROGRAM; it is what the build step runs.

if(CMAKE_SCRIPT_MODE_FILE)
  foreach(var PROGRAM DIRECTORY)
    if(NOT DEFINED ${var})
      message(FATAL_ERROR "manual.cmake: -D${var}=... is missing")
    endif()
  endforeach()
  # A leak found at the exit of a sanitizer build's run is for the tests to
  # report, not a reason to fail the build.
  set(ENV{ASAN_OPTIONS} "$ENV{ASAN_OPTIONS}:detect_leaks=0")
  function(print_into name)
    set(temporary "${DIRECTORY}/${name}.tmp")
    execute_process(COMMAND ${EMULATOR} "${PROGRAM}" ${ARGN} OUTPUT_FILE "${temporary}"
                    ERROR_VARIABLE error RESULT_VARIABLE status)
    if(NOT status EQUAL 0)
      file(REMOVE "${temporary}")
      message(FATAL_ERROR "manual.cmake: '${PROGRAM} ${ARGN}' failed (${status}): ${error}")
    endif()
    file(RENAME "${temporary}" "${DIRECTORY}/${name}")
  endfunction()
  print_into(vmpray.1 --manpage)
  print_into(vmpray.bash-completion --completion bash)
  return()
endif()

function(vmpray_add_manual target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "DIRECTORY" "")
  if(CMAKE_CROSSCOMPILING AND NOT CMAKE_CROSSCOMPILING_EMULATOR)
    message(STATUS "${target}: a cross build with no emulator to run it: no manual page or completion script")
    return()
  endif()
  set(page "${arg_DIRECTORY}/vmpray.1")
  set(completion "${arg_DIRECTORY}/vmpray.bash-completion")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${target}> -DDIRECTORY=${arg_DIRECTORY}
            -DEMULATOR=${CMAKE_CROSSCOMPILING_EMULATOR} -P ${CMAKE_CURRENT_FUNCTION_LIST_FILE}
    BYPRODUCTS ${page} ${completion}
    COMMENT "Printing the manual page and the bash completion of ${target}"
    VERBATIM)
  install(FILES ${page} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  install(FILES ${completion} DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME vmpray)
endfunction()
