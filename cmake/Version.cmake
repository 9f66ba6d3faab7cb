# --version for every program: the project version (project(... VERSION)) and
# `git describe --always --dirty` of the source tree, or "unknown" where the
# source is not a git checkout (a source tarball).
#
#   resolver_version_info  custom target run by every build: rewrites the two
#                          files below only when their text changes, so a
#                          new commit relinks the programs and nothing else
#                          does (cmake/WriteVersionInfo.cmake).
#   RESOLVER_VERSION_HEADER  generated C++ header, included by exactly one file
#                          (daemon/service/program_version.cpp), so a new git
#                          description recompiles one file.
#   RESOLVER_VERSION_FILE  the same line as plain text for the bash launcher
#                          resolver-spy (bin/../share/resolver-bench/VERSION).
find_package(Git QUIET)
set(RESOLVER_VERSION_HEADER ${PROJECT_BINARY_DIR}/generated/version/resolver_version_info.h)
set(RESOLVER_VERSION_FILE ${PROJECT_BINARY_DIR}/share/resolver-bench/VERSION)

set(resolver_version_args
  -DPROJECT_VERSION=${PROJECT_VERSION}
  -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
  -DGIT_EXECUTABLE=${GIT_EXECUTABLE}
  -DHEADER=${RESOLVER_VERSION_HEADER}
  -DTEXT=${RESOLVER_VERSION_FILE})
# Once now, so configure prints the version and the files exist before any build.
execute_process(COMMAND ${CMAKE_COMMAND} ${resolver_version_args} -P ${CMAKE_CURRENT_LIST_DIR}/WriteVersionInfo.cmake
                COMMAND_ERROR_IS_FATAL ANY)
file(STRINGS ${RESOLVER_VERSION_FILE} resolver_version_line LIMIT_COUNT 1)
message(STATUS "resolver bench version: ${resolver_version_line}")

# And on every build: a commit or an edit after configure changes the description.
add_custom_target(resolver_version_info
  COMMAND ${CMAKE_COMMAND} ${resolver_version_args} -P ${CMAKE_CURRENT_LIST_DIR}/WriteVersionInfo.cmake
  BYPRODUCTS ${RESOLVER_VERSION_HEADER} ${RESOLVER_VERSION_FILE}
  VERBATIM)

# What program_version.cpp needs: the generated header's folder.
add_library(resolver_version_headers INTERFACE)
add_dependencies(resolver_version_headers resolver_version_info)
target_include_directories(resolver_version_headers INTERFACE ${PROJECT_BINARY_DIR}/generated/version)
