# CMAKE_PROJECT_INCLUDE hook for building tests/fuzz and tests/bad_input before
# tests/CMakeLists.txt lists them (run_fuzzers.sh uses it only in that case):
#   cmake -DCMAKE_PROJECT_INCLUDE=<repo>/tests/fuzz/attach_test_dirs.cmake \
#         -DRESOLVER_ATTACH_TEST_DIRS="fuzz;bad_input" ...
# The folders' CMakeLists.txt are include()d at the end of the top-level
# CMakeLists.txt (CMake forbids add_subdirectory there), after every library
# target exists; they use CMAKE_CURRENT_LIST_DIR so both ways work.
function(_resolver_attach_test_dirs)
  foreach(dir IN LISTS RESOLVER_ATTACH_TEST_DIRS)
    include(${CMAKE_SOURCE_DIR}/tests/${dir}/CMakeLists.txt)
  endforeach()
endfunction()
cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL _resolver_attach_test_dirs)
