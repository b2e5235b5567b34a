# Text files compiled into the program (the replay page's script and style):
# at build time a file's text becomes a C++ source in the build folder that
# defines `const char* const NAMESPACE::NAME`, so the program needs the file
# only to be built, never to run.
# Invariants: the text goes in byte for byte, less the file's opening comment
# (its leading `//` lines, or its leading `/* ... */` block) and the blank
# lines after it; it is one raw string literal whose closing sequence
# )vmpray_embed" must not occur in the text (the build fails, naming the file,
# if it does); the source is generated again whenever the file (or this
# script) changes. The generated source includes HEADER, which must declare
# the constant `extern` (a namespace-scope const has internal linkage
# otherwise).
#
# Two uses of this one file:
#   include(cmake/embed_text.cmake) defines
#     vmpray_embed_text(TARGET NAME ns::name FILE path HEADER dir/header.hpp)
#   which adds the generated source to TARGET; FILE is relative to the
#   calling folder, HEADER is as an #include names it.
#   cmake -DINPUT=... -DOUTPUT=... -DNAME=ns::name -DHEADER=... -DSOURCE=...
#         -P cmake/embed_text.cmake
#   writes OUTPUT from INPUT (SOURCE: INPUT as messages and the generated
#   comment name it); it is what the function's build step runs.

if(CMAKE_SCRIPT_MODE_FILE)
  foreach(var INPUT OUTPUT NAME HEADER SOURCE)
    if(NOT DEFINED ${var})
      message(FATAL_ERROR "embed_text.cmake: -D${var}=... is missing")
    endif()
  endforeach()
  if(NOT NAME MATCHES "^(([A-Za-z_][A-Za-z0-9_]*::)*)([A-Za-z_][A-Za-z0-9_]*)$")
    message(FATAL_ERROR "embed_text.cmake: NAME '${NAME}' is not a C++ name")
  endif()
  set(identifier "${CMAKE_MATCH_3}")
  string(REGEX REPLACE "::$" "" namespace "${CMAKE_MATCH_1}")

  file(READ "${INPUT}" text)
  # The opening comment says what the file is for; the program has no use for it.
  if(text MATCHES "^//")
    string(REGEX REPLACE "^(//[^\n]*\n)+" "" text "${text}")
  elseif(text MATCHES "^/\\*")
    string(FIND "${text}" "*/" end)
    if(end EQUAL -1)
      message(FATAL_ERROR "${SOURCE}: its opening /* comment is not closed")
    endif()
    math(EXPR end "${end} + 2")
    string(SUBSTRING "${text}" ${end} -1 text)
  endif()
  string(REGEX REPLACE "^[ \t]*\n+" "" text "${text}")

  set(delimiter "vmpray_embed")
  string(FIND "${text}" ")${delimiter}\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${SOURCE} contains )${delimiter}\", which would end the C++ raw string "
                        "its text is embedded in (cmake/embed_text.cmake); write it otherwise")
  endif()

  set(open "")
  set(close "")
  if(NOT namespace STREQUAL "")
    set(open "namespace ${namespace} {\n\n")
    set(close "\n}  // namespace ${namespace}\n")
  endif()
  file(WRITE "${OUTPUT}"
       "// Generated from ${SOURCE} by cmake/embed_text.cmake: edit that file, not this one.\n"
       "#include \"${HEADER}\"\n\n${open}"
       "const char* const ${identifier} = R\"${delimiter}(${text})${delimiter}\";\n${close}")
  return()
endif()

function(vmpray_embed_text target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "NAME;FILE;HEADER" "")
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_NAME OR NOT arg_FILE OR NOT arg_HEADER)
    message(FATAL_ERROR "vmpray_embed_text(${target} NAME ns::name FILE path HEADER dir/header.hpp)")
  endif()
  get_filename_component(input "${arg_FILE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  file(RELATIVE_PATH source "${PROJECT_SOURCE_DIR}" "${input}")
  file(RELATIVE_PATH local "${CMAKE_CURRENT_SOURCE_DIR}" "${input}")
  if(local MATCHES "^\\.\\./")
    message(FATAL_ERROR "vmpray_embed_text: ${arg_FILE} is not under ${CMAKE_CURRENT_SOURCE_DIR}")
  endif()
  set(output "${CMAKE_CURRENT_BINARY_DIR}/embedded/${local}.cpp")
  add_custom_command(
    OUTPUT "${output}"
    COMMAND "${CMAKE_COMMAND}" "-DINPUT=${input}" "-DOUTPUT=${output}" "-DNAME=${arg_NAME}"
            "-DHEADER=${arg_HEADER}" "-DSOURCE=${source}" -P "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    DEPENDS "${input}" "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    COMMENT "Embedding ${source}"
    VERBATIM)
  target_sources(${target} PRIVATE "${output}")
endfunction()
