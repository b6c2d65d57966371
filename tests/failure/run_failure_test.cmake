# Runs EXECUTABLE on PARAMETER_FILE in WORK_DIR and checks that it fails cleanly:
# a non-zero exit code (not a signal, not an abort) and a message matching the
# regular expression in the parameter file's first line, `# EXPECT: <regex>`.
file(STRINGS ${PARAMETER_FILE} _first LIMIT_COUNT 1)
if(NOT _first MATCHES "^# EXPECT: (.*)$")
  message(FATAL_ERROR "${PARAMETER_FILE}: the first line must be '# EXPECT: <regex>'")
endif()
set(_expected "${CMAKE_MATCH_1}")
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
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
