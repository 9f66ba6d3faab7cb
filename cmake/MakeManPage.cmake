# One man page from a program's --help and --version (run with cmake -P; see
# Packaging.cmake). Inputs (-D): HELP2MAN, GZIP, PROGRAM, NAME, SUMMARY, OUTPUT
# (NAME.1.gz).
#
# Programs with subcommands (CLI11 lists them under "SUBCOMMANDS:" in --help,
# e.g. resolver-model fit/explain/report) get each subcommand's --help as a
# section of the same page, so `man resolver-model` has every option.
#
# help2man fills (re-flows) every paragraph; the programs' EXAMPLES sections
# (and what follows them: catalogs, exit codes) are laid out by hand, one
# command a line, so that section is set verbatim (.nf) as --help shows it.
include(${CMAKE_CURRENT_LIST_DIR}/ScriptHelpers.cmake)
resolver_require_defines(MakeManPage.cmake HELP2MAN GZIP PROGRAM NAME SUMMARY OUTPUT)

get_filename_component(out_dir "${OUTPUT}" DIRECTORY)
set(page "${out_dir}/${NAME}.1")
set(include_file "${out_dir}/${NAME}.h2m")
file(MAKE_DIRECTORY "${out_dir}")

execute_process(COMMAND "${PROGRAM}" --help OUTPUT_VARIABLE help RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NAME} --help failed (${rc}): ${err}")
endif()

# Subcommand names: the indented first words of the lines after CLI11's
# "Subcommands:" ("SUBCOMMANDS:" in newer CLI11).
set(subcommands "")
string(TOLOWER "${help}" help_lower)
string(FIND "${help_lower}" "\nsubcommands:\n" at)
if(at GREATER -1)
  math(EXPR at "${at} + 14")
  string(SUBSTRING "${help}" ${at} -1 rest)
  string(REPLACE "\n" ";" lines "${rest}")
  foreach(line IN LISTS lines)
    if(line MATCHES "^  +([a-z][a-z0-9_-]*)( |$)")
      list(APPEND subcommands "${CMAKE_MATCH_1}")
    elseif(NOT line MATCHES "^ " AND NOT line STREQUAL "")
      break()  # the next section
    endif()
  endforeach()
endif()

# help2man's --include file: [SECTION] headers followed by roff text.
set(include_args "")
if(subcommands)
  set(include_text "[SUBCOMMANDS]\n")
  set(include_args "--include=${include_file}")
  foreach(sub IN LISTS subcommands)
    execute_process(COMMAND "${PROGRAM}" ${sub} --help OUTPUT_VARIABLE sub_help RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${NAME} ${sub} --help failed (${rc}): ${err}")
    endif()
    # CLI11 prints argv[0]: the build path. The page names the installed program.
    string(REPLACE "${PROGRAM}" "${NAME}" sub_help "${sub_help}")
    # Verbatim (no fill), with roff's escape character and leading dots made literal.
    string(REPLACE "\\" "\\e" sub_help "${sub_help}")
    string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" sub_help "${sub_help}")
    string(APPEND include_text ".SS \"${NAME} ${sub}\"\n.nf\n${sub_help}\n.fi\n")
  endforeach()
  file(WRITE "${include_file}" "${include_text}")
endif()

# SOURCE_DATE_EPOCH (reproducible builds) fixes the page's date if set.
execute_process(
  COMMAND "${HELP2MAN}" --no-info --section=1 "--name=${SUMMARY}" ${include_args}
          "--output=${page}" "${PROGRAM}"
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man ${NAME} failed (${rc}): ${err}")
endif()
# EXAMPLES (up to the next .SH) verbatim: drop help2man's paragraph macros.
file(READ "${page}" roff)
string(FIND "${roff}" "\n.SH EXAMPLES\n" at)
if(at GREATER -1)
  math(EXPR body_at "${at} + 14")
  string(SUBSTRING "${roff}" 0 ${body_at} head)
  string(SUBSTRING "${roff}" ${body_at} -1 body)
  string(FIND "${body}" "\n.SH " end)
  set(tail "")
  if(end GREATER -1)
    math(EXPR end "${end} + 1")
    string(SUBSTRING "${body}" ${end} -1 tail)
    string(SUBSTRING "${body}" 0 ${end} body)
  endif()
  # Macro lines may follow each other; a pass removes every other one, so repeat.
  set(body "\n${body}")
  set(previous "")
  while(NOT body STREQUAL previous)
    set(previous "${body}")
    string(REGEX REPLACE "\n\\.(IP|HP|TP)\n" "\n" body "${body}")
    string(REGEX REPLACE "\n\\.PP\n" "\n\n" body "${body}")
  endwhile()
  string(SUBSTRING "${body}" 1 -1 body)
  file(WRITE "${page}" "${head}.nf\n${body}.fi\n${tail}")
endif()

# -n: no name or time stamp in the gzip header, so the same page gives the same bytes.
execute_process(COMMAND "${GZIP}" -9nf "${page}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "gzip ${page} failed (${rc})")
endif()
file(REMOVE "${include_file}")
