# Shared build settings: warnings, sanitizers and the add_unit_test() helper.

# Every project target links resolver_build_flags (PRIVATE) to get the same warnings.
add_library(resolver_build_flags INTERFACE)
target_compile_options(resolver_build_flags INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wdouble-promotion -Wnon-virtual-dtor -Woverloaded-virtual)
if(RESOLVER_WERROR)
  target_compile_options(resolver_build_flags INTERFACE -Werror)
endif()
if(RESOLVER_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()

include(GoogleTest)

# resolver_unit_test_uses(target ...): these targets are what a test labelled "unit"
# runs. The target unit_tests (top CMakeLists.txt) builds them all and nothing else: the
# sanitizer stage of tools/run-tests.sh runs only the unit label, and building every
# program, benchmark and integration helper there cost it minutes for no test.
function(resolver_unit_test_uses)
  set_property(GLOBAL APPEND PROPERTY RESOLVER_UNIT_TEST_TARGETS ${ARGN})
endfunction()

# add_unit_test(NAME SOURCES a.cpp ... [LIBS lib ...] [LABELS label ...])
# Builds a GoogleTest executable and registers each TEST with ctest.
# The default label is "unit"; integration tests pass LABELS integration.
function(add_unit_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  if("unit" IN_LIST ARG_LABELS)
    resolver_unit_test_uses(${name})
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main resolver_build_flags)
  target_compile_definitions(${name} PRIVATE
    RESOLVER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    RESOLVER_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared"
    RESOLVER_BINARY_DIR="${PROJECT_BINARY_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
    PROPERTIES LABELS "${ARG_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()

# Project includes are spelled from the top: #include "drivers/can_frame.h".
add_library(resolver_headers INTERFACE)
target_include_directories(resolver_headers INTERFACE ${PROJECT_SOURCE_DIR})
