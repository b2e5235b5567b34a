# Applies VMPRAY_SANITIZE (e.g. "address,undefined" or "thread") to every target.
if(VMPRAY_SANITIZE)
  add_compile_options(-fsanitize=${VMPRAY_SANITIZE} -fno-omit-frame-pointer -g)
  add_link_options(-fsanitize=${VMPRAY_SANITIZE})
  if(VMPRAY_SANITIZE MATCHES "undefined")
    # GCC leaves a float converted to an int that cannot hold it (or NaN)
    # out of "undefined"; clang puts it in. Ask for it by name, and stop at
    # the first report of either.
    add_compile_options(-fsanitize=float-cast-overflow -fno-sanitize-recover=undefined,float-cast-overflow)
    add_link_options(-fsanitize=float-cast-overflow)
  endif()
endif()
