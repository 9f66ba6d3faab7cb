# Build step of resolver_python (run with cmake -P): the Python package
# resolver_lcm in OUTPUT_DIR = the handwritten modules (SOURCE_DIR/resolver_lcm)
# + the message classes lcm-gen --python makes from LCM_DIR/*.lcm, as the
# subpackage resolver_lcm.resolver (--package-prefix; fingerprints unchanged).
#
# Inputs (-D): LCM_GEN, LCM_DIR, SOURCE_DIR, OUTPUT_DIR, STAMP.
# OUTPUT_DIR/resolver_lcm is wiped first: a type removed from the .lcm files
# must not survive as a stale module.
include(${CMAKE_CURRENT_LIST_DIR}/../../cmake/ScriptHelpers.cmake)
resolver_require_defines(build_python_package.cmake LCM_GEN LCM_DIR SOURCE_DIR OUTPUT_DIR STAMP)
resolver_lcm_files(lcm_files ${LCM_DIR} build_python_package.cmake)

set(package ${OUTPUT_DIR}/resolver_lcm)
set(generated ${OUTPUT_DIR}/.lcmgen)
file(REMOVE_RECURSE ${package} ${generated})
file(MAKE_DIRECTORY ${generated})

execute_process(COMMAND ${LCM_GEN} --python --package-prefix resolver_lcm --ppath ${generated} ${lcm_files}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "resolver_lcm: lcm-gen --python failed (${rc})")
endif()
if(NOT EXISTS ${generated}/resolver_lcm/resolver/__init__.py)
  message(FATAL_ERROR "resolver_lcm: lcm-gen wrote no ${generated}/resolver_lcm/resolver/__init__.py")
endif()

# Our own __init__.py and modules; then only the generated subpackage (lcm-gen's
# resolver_lcm/__init__.py is an empty placeholder for ours).
file(GLOB handwritten ${SOURCE_DIR}/resolver_lcm/*.py)
file(COPY ${handwritten} DESTINATION ${package})
file(COPY ${generated}/resolver_lcm/resolver DESTINATION ${package})
file(REMOVE_RECURSE ${generated})
file(TOUCH ${STAMP})
