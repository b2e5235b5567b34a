# What `cmake --install` puts beside the program, and the Debian package
# `cpack -G DEB` makes of it (run in the build folder, or
# `cpack --config BUILD/CPackConfig.cmake`): vmpray_VERSION_ARCH.deb.
# Invariants: the package holds exactly what `cmake --install` installs
# (usr/bin/vmpray, its manual page and bash completion, README.md and
# LICENSE in usr/share/doc/vmpray) and is version PROJECT_VERSION; its
# Depends name every shared library the program links, so that
# `apt-get install ./vmpray_*.deb` on a bare Debian pulls them in: found by
# dpkg-shlibdeps (package dpkg-dev, which needs `file`) when installed, else
# (or with -DVMPRAY_PACKAGE_SHLIBDEPS=OFF) the list below, Debian 12's.
# fonts-dejavu-core is always named: the pictures are written and measured
# in DejaVu Sans (app/viz/text.hpp).
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

set(VMPRAY_PACKAGE_MAINTAINER "vmpray maintainers <vmpray-maintainers@example.org>"
    CACHE STRING "The Maintainer field of the Debian package")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vmpray)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "the vmpray authors")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "parallel ray tracer on a simulated distributed-memory machine (VM_pRAY)")
set(CPACK_PACKAGE_DESCRIPTION
    "vmpray re-creates VM_pRAY (Badouel and Priol, 1990), a ray tracer for distributed-memory parallel "
    "computers whose scene database is spread over the processors as object pages in a software shared "
    "virtual memory. It simulates such a machine (hypercube, mesh, torus, ring or complete graph) as a CSP "
    "program of lightweight processes, renders NFF and built-in scenes, reproduces the paper's tables, "
    "and runs over MPI on several machines.")
string(REPLACE ";" "" CPACK_PACKAGE_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION}")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${VMPRAY_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS openmpi-bin)  # mpirun, to run over several processes or machines

option(VMPRAY_PACKAGE_SHLIBDEPS "Let dpkg-shlibdeps find the package's Depends when it is installed" ON)
find_program(VMPRAY_DPKG_SHLIBDEPS dpkg-shlibdeps)
find_program(VMPRAY_FILE file)
if(VMPRAY_PACKAGE_SHLIBDEPS AND VMPRAY_DPKG_SHLIBDEPS AND VMPRAY_FILE)
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "fonts-dejavu-core")
else()
  # What dpkg-shlibdeps finds on Debian 12 for the libraries `objdump -p` lists as NEEDED.
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
      "libboost-context1.74.0 (>= 1.74.0+ds1), libboost-fiber1.74.0 (>= 1.74.0+ds1), "
      "libboost-program-options1.74.0 (>= 1.74.0+ds1), libc6 (>= 2.35), libcairo2 (>= 1.15.10), libgcc-s1 (>= 3.4), "
      "libopenmpi3 (>= 4.1.4), libpng16-16 (>= 1.6.2-1), libstdc++6 (>= 12), zlib1g (>= 1:1.1.4), fonts-dejavu-core")
  string(REPLACE ";" "" CPACK_DEBIAN_PACKAGE_DEPENDS "${CPACK_DEBIAN_PACKAGE_DEPENDS}")
endif()
include(CPack)
