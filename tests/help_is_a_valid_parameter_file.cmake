# `lacerta --help` must print a documented parameter file that lacerta itself accepts:
# run it (briefly) and expect success.
execute_process(COMMAND ${EXECUTABLE} --help OUTPUT_FILE ${WORK_DIR}/help.prm RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "lacerta --help failed: ${result}")
endif()
file(READ ${WORK_DIR}/help.prm text)
foreach(kind "rk4" "symplectic_euler" "velocity_verlet" "explicit_euler" "linear springs"
             "implicit function" "moving handle" "force handle" "boundary id" "statistics" "vtu")
  if(NOT text MATCHES "`${kind}'")
    message(FATAL_ERROR "lacerta --help does not document the plugin '${kind}'")
  endif()
endforeach()
file(APPEND ${WORK_DIR}/help.prm "set End time = 0.001\nset Output directory = help_run\nset Test mode = true\n")
execute_process(COMMAND ${EXECUTABLE} ${WORK_DIR}/help.prm WORKING_DIRECTORY ${WORK_DIR}
  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "lacerta rejected its own --help output:\n${out}${err}")
endif()
