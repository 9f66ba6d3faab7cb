# Installing and packaging (included at the end of the top-level CMakeLists.txt,
# after every target exists):
#   - every program: linked with the --version helper, installed to bin/, and a
#     man page made from its --help by help2man (build/man/man1/*.1.gz);
#   - the bench DBC, the LCM definitions, the generated C++ headers, the Java
#     types jar (when Java was found), the Python package resolver_lcm, the
#     demo configs, the systemd units (systemd/CMakeLists.txt) and the docs;
#   - CPack: `cpack -G DEB` in the build dir writes resolver-bench_<version>_<arch>.deb,
#     installing under /usr, with its shared-library dependencies found by
#     dpkg-shlibdeps (dpkg-dev) plus what the scripts need.
# Layout (prefix /usr):
#   bin/                                  resolverd resolver-sim resolver-echo resolver-model
#                                         resolver-accuracy resolver-spy
#   include/resolver/*.hpp                lcm-gen C++ types (need liblcm-dev)
#   lib/python3/dist-packages/resolver_lcm   Python types + log reader (/usr/local: lib/python3.X/...)
#   lib/python3/dist-packages/resolver_bench the fleet's Dask client (needs python3-distributed: Suggests)
#   lib/systemd/system/resolverd*.service
#   share/java/resolver-types.jar         lcm-gen Java types (resolver-spy)
#   share/resolver-bench/                 resolver_bench.dbc, lcm/resolver/*.lcm, demo/*.toml,
#                                         systemd-network/ (examples), VERSION
#   share/man/man1/*.1.gz, share/doc/resolver-bench/ (README, systemd/README.md, examples/)

set(RESOLVER_DATADIR ${CMAKE_INSTALL_DATADIR}/resolver-bench)

# --- programs ---------------------------------------------------------------
# Off by default in a sanitizer build: it is never installed, and help2man would
# run instrumented programs at build time (a leak report would fail the build).
if(RESOLVER_SANITIZE)
  set(resolver_man_default OFF)
else()
  set(resolver_man_default ON)
endif()
option(RESOLVER_MAN_PAGES "man pages from each program's --help (needs help2man)" ${resolver_man_default})
find_program(HELP2MAN help2man)
find_program(GZIP gzip)
set(RESOLVER_MAN_DIR ${PROJECT_BINARY_DIR}/man/man1)
if(RESOLVER_MAN_PAGES AND NOT (HELP2MAN AND GZIP))
  message(STATUS "help2man or gzip not found: no man pages (Debian: apt-get install help2man)")
  set(RESOLVER_MAN_PAGES OFF)
endif()
set(resolver_man_pages "")

# resolver_add_program(NAME TARGET target | SCRIPT path  SUMMARY "one line")
# Installs the program and makes its man page. C++ programs also get the
# --version helper (daemon/service/program_version.h) and the exit-code rule
# (daemon/service/program_errors.h) linked in here, so the list of programs lives
# in one place.
function(resolver_add_program name)
  cmake_parse_arguments(ARG "" "TARGET;SCRIPT;SUMMARY" "" ${ARGN})
  if(ARG_TARGET)
    target_link_libraries(${ARG_TARGET} PRIVATE resolver_version resolver_program_errors)
    install(TARGETS ${ARG_TARGET} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    set(program $<TARGET_FILE:${ARG_TARGET}>)
    set(depends ${ARG_TARGET})
  else()
    install(PROGRAMS ${ARG_SCRIPT} DESTINATION ${CMAKE_INSTALL_BINDIR})
    set(program ${ARG_SCRIPT})
    set(depends ${ARG_SCRIPT})
  endif()
  if(RESOLVER_MAN_PAGES)
    set(page ${RESOLVER_MAN_DIR}/${name}.1.gz)
    add_custom_command(
      OUTPUT ${page}
      COMMAND ${CMAKE_COMMAND} -DHELP2MAN=${HELP2MAN} -DGZIP=${GZIP} -DPROGRAM=${program}
              -DNAME=${name} -DSUMMARY=${ARG_SUMMARY} -DOUTPUT=${page}
              -P ${PROJECT_SOURCE_DIR}/cmake/MakeManPage.cmake
      DEPENDS ${depends} ${RESOLVER_VERSION_FILE} ${PROJECT_SOURCE_DIR}/cmake/MakeManPage.cmake
              ${PROJECT_SOURCE_DIR}/cmake/ScriptHelpers.cmake
      COMMENT "help2man: ${name}.1"
      VERBATIM)
    set(resolver_man_pages ${resolver_man_pages} ${page} PARENT_SCOPE)
  endif()
endfunction()

resolver_add_program(resolverd TARGET resolverd
  SUMMARY "resolver bench daemon: CAN resolver frames -> calibration -> LCM")
resolver_add_program(resolver-sim TARGET resolver_sim_cli
  SUMMARY "simulate the resolver bench and write its CAN traffic as a candump log")
resolver_add_program(resolver-echo TARGET resolver_echo
  SUMMARY "print LCM messages from a log or the bus as JSON lines")
resolver_add_program(resolver-model TARGET resolver_model_cli
  SUMMARY "fit the effect model to a log, show where it fails, name the missing effect")
resolver_add_program(resolver-accuracy TARGET resolver_accuracy
  SUMMARY "estimator accuracy against the Cramer-Rao bound on simulated benches")
resolver_add_program(resolver-spy SCRIPT ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/resolver-spy
  SUMMARY "lcm-spy with the resolver message types, on Java 9 and later")

if(RESOLVER_MAN_PAGES)
  add_custom_target(resolver_man_pages ALL DEPENDS ${resolver_man_pages})
  install(FILES ${resolver_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
endif()
# Every program's --help (usage names the program, examples per resolver-model
# subcommand) and, when they are made, the man pages' EXAMPLES sections set one
# command a line (tests/install/test_help.py). Registered here, where the
# programs and RESOLVER_MAN_PAGES are known.
if(RESOLVER_BUILD_TESTS)
  set(help_test_man "")
  if(RESOLVER_MAN_PAGES)
    set(help_test_man --man ${RESOLVER_MAN_DIR})
  endif()
  add_test(NAME program_help
    COMMAND ${RESOLVER_SYSTEM_PYTHON3} ${PROJECT_SOURCE_DIR}/tests/install/test_help.py
            --bin ${CMAKE_RUNTIME_OUTPUT_DIRECTORY} ${help_test_man})
  set_tests_properties(program_help PROPERTIES LABELS integration TIMEOUT 120)
endif()
# resolver-spy --version reads it (bin/../share/resolver-bench/VERSION).
install(FILES ${RESOLVER_VERSION_FILE} DESTINATION ${RESOLVER_DATADIR})

# --- data, types, docs --------------------------------------------------------
install(FILES ${PROJECT_SOURCE_DIR}/proto/resolver_bench.dbc DESTINATION ${RESOLVER_DATADIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/proto/resolver DESTINATION ${RESOLVER_DATADIR}/lcm
        FILES_MATCHING PATTERN "*.lcm")
# proto/CMakeLists.txt's lcm-gen output folder (LCM_GEN_DIR there).
install(DIRECTORY ${PROJECT_BINARY_DIR}/proto/lcmgen/resolver DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
install(FILES ${PROJECT_SOURCE_DIR}/tools/demo/demo_bench.toml ${PROJECT_SOURCE_DIR}/tools/demo/model_with_dead_time.toml
        DESTINATION ${RESOLVER_DATADIR}/demo)
if(TARGET resolver_spy_types)  # tools/spy/CMakeLists.txt, when javac, jar and lcm.jar were found
  install(FILES ${PROJECT_BINARY_DIR}/share/resolver-types.jar DESTINATION ${CMAKE_INSTALL_DATADIR}/java)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/python/examples/lcmlog_to_arrays.py
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# Python: the folder depends on the prefix chosen at install time (InstallForPrefix.cmake).
# Debian's python3 (tools/python/CMakeLists.txt) decides the X of /usr/local/lib/python3.X.
execute_process(COMMAND ${RESOLVER_SYSTEM_PYTHON3} -c "import sys; print(sys.version_info.minor)"
                OUTPUT_VARIABLE resolver_python_minor OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
set(RESOLVER_PYTHON_INSTALL_DIR "" CACHE STRING
    "where resolver_lcm goes, relative to the prefix; empty = lib/python3/dist-packages for /usr, else lib/python3.X/dist-packages")
install(CODE "include(\"${PROJECT_SOURCE_DIR}/cmake/InstallForPrefix.cmake\")
  resolver_install_python_package(\"${RESOLVER_PYTHON_BUILD_DIR}/resolver_lcm\" \"${RESOLVER_PYTHON_INSTALL_DIR}\"
                                  \"${resolver_python_minor}\")
  resolver_install_python_package(\"${RESOLVER_PYTHON_BUILD_DIR}/resolver_bench\" \"${RESOLVER_PYTHON_INSTALL_DIR}\"
                                  \"${resolver_python_minor}\")")

# --- the .deb ------------------------------------------------------------------
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME resolver-bench)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "resolver bench maintainers <resolver-bench@localhost>" CACHE STRING
    "Maintainer: field of the .deb")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "resolver calibration daemon and tools for motor test benches")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "resolverd reads resolver sin/cos envelopes, R/D converter angles and phase
currents from CAN (SocketCAN or candump logs), estimates and compensates the
resolver's imperfections and publishes angle, estimates, dq currents, model
fits and health on LCM. With the bench simulator, the model discovery tool,
LCM types for C++, Java and Python, and systemd units.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # resolver-bench_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION electronics)
# Installed with DESTDIR=<staging> and the final prefix /usr (CPACK_INSTALL_PREFIX
# with CPACK_SET_DESTDIR; the CMAKE_INSTALL_PREFIX of this build does not matter),
# so InstallForPrefix.cmake sees /usr: ExecStart=/usr/bin/resolverd.
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)
set(CPACK_STRIP_FILES ON)
# Depends: the shared libraries the programs link (liblcm1, libfmt9, libstdc++6, ...),
# found by dpkg-shlibdeps, plus the interpreter of the Python package.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3")
# resolver-spy: a Swing GUI on Java with LCM's and jchart2d's jars; numpy makes
# resolver_lcm's columns arrays. Recommended (apt installs them unless
# --no-install-recommends keeps a headless bench lean).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "default-jre | java-runtime, liblcm-java, libjchart2d-java, python3-numpy")
# lcm-logger/lcm-logplayer, candump/canplayer, the C++ headers' lcm_coretypes.h.; Dask for python3 -m resolver_bench.fleet.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "liblcm-bin, can-utils, liblcm-dev, python3-distributed")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/cmake/deb/postinst ${PROJECT_SOURCE_DIR}/cmake/deb/prerm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# `cpack --config CPackSourceConfig.cmake`: a source tarball (its builds say "git unknown").
set(CPACK_SOURCE_GENERATOR TXZ)
set(CPACK_SOURCE_PACKAGE_FILE_NAME resolver-bench-${PROJECT_VERSION})
set(CPACK_SOURCE_IGNORE_FILES "/\\\\.git" "/build[^/]*/" "__pycache__" "\\\\.pyc$")
include(CPack)
