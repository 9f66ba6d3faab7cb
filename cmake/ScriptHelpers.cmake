# Helpers for the build-step scripts run with `cmake -P` (WriteVersionInfo,
# MakeManPage, tools/python/build_python_package, tools/spy/build_types_jar).

# resolver_require_defines(SCRIPT VAR...): stops with a message naming SCRIPT
# and the first -DVAR=... that is missing or empty.
function(resolver_require_defines script)
  foreach(var ${ARGN})
    if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
      message(FATAL_ERROR "${script}: -D${var}=... is required")
    endif()
  endforeach()
endfunction()

# resolver_lcm_files(OUT DIR SCRIPT): the *.lcm files in DIR, sorted (the
# generated output must not depend on directory order); stops if there are none.
function(resolver_lcm_files out dir script)
  file(GLOB files ${dir}/*.lcm)
  if(NOT files)
    message(FATAL_ERROR "${script}: no .lcm files in ${dir}")
  endif()
  list(SORT files)
  set(${out} ${files} PARENT_SCOPE)
endfunction()
