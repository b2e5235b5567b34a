# Applies VMPRAY_SANITIZE (e.g. "address,undefined" or "thread") to every target.
if(VMPRAY_SANITIZE)
  add_compile_options(-fsanitize=${VMPRAY_SANITIZE} -fno-omit-frame-pointer -g)
  add_link_options(-fsanitize=${VMPRAY_SANITIZE})
  if(VMPRAY_SANITIZE MATCHES "undefined")
    add_compile_options(-fno-sanitize-recover=undefined)
  endif()
endif()
