# Runs EXECUTABLE on PARAMETER_FILE in WORK_DIR and checks that it fails cleanly:
# a non-zero exit code (not a signal, not an abort) and a message matching the
# regular expression in the parameter file's first line, `# EXPECT: <regex>`.
# Optional lines set up and check the work directory:
#   `# LINK: <path> -> <target>`  makes <path> (relative to WORK_DIR) a symbolic link
#                                 to <target> before the run, such as /dev/full to
#                                 fill the disk at that file;
#   `# VALID: <path> <regex>`     after the run, <path> must exist and match <regex>:
#                                 what was written before the failure stays valid.
file(STRINGS ${PARAMETER_FILE} _first LIMIT_COUNT 1)
if(NOT _first MATCHES "^# EXPECT: (.*)$")
  message(FATAL_ERROR "${PARAMETER_FILE}: the first line must be '# EXPECT: <regex>'")
endif()
set(_expected "${CMAKE_MATCH_1}")
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
file(STRINGS ${PARAMETER_FILE} _links REGEX "^# LINK: ")
foreach(_line ${_links})
  if(NOT _line MATCHES "^# LINK: ([^ ]+) -> ([^ ]+)$")
    message(FATAL_ERROR "${PARAMETER_FILE}: malformed line '${_line}'")
  endif()
  get_filename_component(_directory ${WORK_DIR}/${CMAKE_MATCH_1} DIRECTORY)
  file(MAKE_DIRECTORY ${_directory})
  file(CREATE_LINK ${CMAKE_MATCH_2} ${WORK_DIR}/${CMAKE_MATCH_1} SYMBOLIC)
endforeach()
execute_process(COMMAND ${EXECUTABLE} ${PARAMETER_FILE}
  WORKING_DIRECTORY ${WORK_DIR}
  RESULT_VARIABLE _result
  OUTPUT_VARIABLE _out
  ERROR_VARIABLE _err
  TIMEOUT 120)
set(_all "${_out}${_err}")
message("${_all}")
if(_result EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit code, got 0")
endif()
if(NOT _result MATCHES "^[0-9]+$" OR _result GREATER 125)
  message(FATAL_ERROR "the program crashed (${_result}) instead of exiting cleanly")
endif()
if(_all MATCHES "Stacktrace|violated condition|Aborted")
  message(FATAL_ERROR "the message is an assertion dump, not a clear error")
endif()
if(NOT _all MATCHES "${_expected}")
  message(FATAL_ERROR "the output does not contain the expected message: ${_expected}")
endif()
file(STRINGS ${PARAMETER_FILE} _valid REGEX "^# VALID: ")
foreach(_line ${_valid})
  if(NOT _line MATCHES "^# VALID: ([^ ]+) (.+)$")
    message(FATAL_ERROR "${PARAMETER_FILE}: malformed line '${_line}'")
  endif()
  set(_regex "${CMAKE_MATCH_2}")
  if(NOT EXISTS ${WORK_DIR}/${CMAKE_MATCH_1})
    message(FATAL_ERROR "${CMAKE_MATCH_1} was not kept")
  endif()
  file(READ ${WORK_DIR}/${CMAKE_MATCH_1} _contents)
  if(NOT _contents MATCHES "${_regex}")
    message(FATAL_ERROR "${CMAKE_MATCH_1} does not match ${_regex}:\n${_contents}")
  endif()
endforeach()
