# Build step of resolver_spy_types (run with cmake -P): proto/resolver/*.lcm ->
# Java sources (lcm-gen --java) -> classes (javac against lcm.jar) -> one jar.
#
# Inputs (-D): LCM_GEN, JAVAC, JAR, LCM_JAR, LCM_DIR, WORK_DIR, OUTPUT.
# WORK_DIR is wiped first so a struct removed from the .lcm files cannot
# survive as a stale class in the jar.
include(${CMAKE_CURRENT_LIST_DIR}/../../cmake/ScriptHelpers.cmake)
resolver_require_defines(build_types_jar.cmake LCM_GEN JAVAC JAR LCM_JAR LCM_DIR WORK_DIR OUTPUT)
resolver_lcm_files(lcm_files ${LCM_DIR} build_types_jar.cmake)

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/java ${WORK_DIR}/classes)

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "resolver-types.jar: ${what} failed (${rc})")
  endif()
endfunction()

run_step("lcm-gen --java" ${LCM_GEN} --java --jpath ${WORK_DIR}/java ${lcm_files})

file(GLOB_RECURSE java_files ${WORK_DIR}/java/*.java)
if(NOT java_files)
  message(FATAL_ERROR "resolver-types.jar: lcm-gen produced no .java files")
endif()
list(SORT java_files)
# -nowarn: the generated code is not ours to keep warning-free.
run_step("javac" ${JAVAC} -nowarn -encoding UTF-8 -cp ${LCM_JAR}
         -d ${WORK_DIR}/classes ${java_files})

get_filename_component(out_dir ${OUTPUT} DIRECTORY)
file(MAKE_DIRECTORY ${out_dir})
# Write to a temporary name, then rename: an interrupted build never leaves a
# truncated jar that looks up to date.
file(REMOVE ${OUTPUT}.tmp)
run_step("jar" ${JAR} cf ${OUTPUT}.tmp -C ${WORK_DIR}/classes .)
file(RENAME ${OUTPUT}.tmp ${OUTPUT})
