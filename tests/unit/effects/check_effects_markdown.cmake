# ctest script: docs/EFFECTS.md must be exactly what `resolver-sim --effects-markdown`
# prints (the registry is the source, the file a generated copy for readers).
# Usage: cmake -DSIM=<resolver-sim> -DDOC=<docs/EFFECTS.md> -P check_effects_markdown.cmake
if(NOT SIM OR NOT DOC)
  message(FATAL_ERROR "check_effects_markdown.cmake: pass -DSIM=<resolver-sim> -DDOC=<markdown file>")
endif()
execute_process(COMMAND "${SIM}" --effects-markdown
  OUTPUT_VARIABLE generated RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${SIM} --effects-markdown failed (exit ${status}): ${err}")
endif()
if(NOT EXISTS "${DOC}")
  message(FATAL_ERROR "${DOC} is missing; generate it from the repository root with:\n"
                      "  build/bin/resolver-sim --effects-markdown > docs/EFFECTS.md")
endif()
file(READ "${DOC}" committed)
if(NOT committed STREQUAL generated)
  message(FATAL_ERROR "${DOC} is out of date with the effect registry; regenerate it from the repository root with:\n"
                      "  build/bin/resolver-sim --effects-markdown > docs/EFFECTS.md\n"
                      "(the program this check ran: ${SIM}) and commit the result.")
endif()
