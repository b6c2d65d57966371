# Runs the study (FEM P1) and the Bullet peer on PARAMETER_FILE and checks the peer's
# error against FEM P1's with CHECK, to the relative TOLERANCE. Arguments: LACERTA, PEER,
# PYTHON, CHECK, TOLERANCE, PARAMETER_FILE, WORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR}/study)
file(REMOVE ${WORK_DIR}/peer_bullet.csv)
foreach(_command "${LACERTA};${PARAMETER_FILE}"
    "${PEER};${PARAMETER_FILE};--output;${WORK_DIR}/peer_bullet.csv"
    "${PYTHON};${CHECK};${WORK_DIR}/study/study.csv;${WORK_DIR}/peer_bullet.csv;${TOLERANCE}")
  execute_process(COMMAND ${_command} WORKING_DIRECTORY ${WORK_DIR}
    RESULT_VARIABLE _result OUTPUT_VARIABLE _output ERROR_VARIABLE _error)
  message("${_output}${_error}")
  if(NOT _result EQUAL 0)
    message(FATAL_ERROR "'${_command}' failed (${_result})")
  endif()
endforeach()
