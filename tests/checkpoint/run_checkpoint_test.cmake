# Checkpoint and restart of a scene (doc/reliability.md, "Checkpoint and restart").
#
# Runs the regression scene SCENE (a tests/*.prm.in) three ways in WORK:
#   full/  uninterrupted;
#   part/  with a checkpoint every EVERY steps (or SECONDS of wall time), stopped after
#          STOP steps
#          ('Checkpoint/Stop after steps'), or, with KILL_AFTER set, killed (SIGKILL)
#          that many seconds after it started, whatever it is doing then (a step, a
#          checkpoint being written);
#   then resumed in part/ ('Checkpoint/Resume = true') to the end.
# The resumed run must end bit for bit equal to the uninterrupted one: statistics.csv,
# solution.pvd and every VTU file compared with zero tolerance, and no other VTU file.
# With CHANGED_ENTRY ('<subsection path>/<entry> = <value>'), a resume with that one
# entry changed must also be refused with a message naming it.
#
# Variables: LACERTA, SCENE, SOURCE_DIR (for @CMAKE_SOURCE_DIR@ in SCENE), WORK, STOP,
# EVERY (or SECONDS: checkpoints by wall time instead of steps), and optionally
# KILL_AFTER and CHANGED_ENTRY.

set(CMAKE_SOURCE_DIR ${SOURCE_DIR})
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
configure_file(${SCENE} ${WORK}/scene.prm @ONLY)

function(write_run name directory checkpoint_lines)
  file(WRITE ${WORK}/${name}.prm
    "include scene.prm\nset Output directory = ${directory}\n"
    "subsection Checkpoint\n${checkpoint_lines}end\n")
endfunction()

function(run name expect_success)
  execute_process(COMMAND ${LACERTA} ${name}.prm
    WORKING_DIRECTORY ${WORK}
    RESULT_VARIABLE result OUTPUT_FILE ${WORK}/${name}.log ERROR_FILE ${WORK}/${name}.err
    TIMEOUT 600)
  if(expect_success AND NOT result EQUAL 0)
    file(READ ${WORK}/${name}.err err)
    message(FATAL_ERROR "the ${name} run failed (${result}):\n${err}")
  endif()
  set(run_result ${result} PARENT_SCOPE)
endfunction()

write_run(full full "")
run(full TRUE)

if(DEFINED SECONDS)
  set(_every "  set Seconds between checkpoints = ${SECONDS}\n")
else()
  set(_every "  set Steps between checkpoints = ${EVERY}\n")
endif()
if(DEFINED KILL_AFTER)
  # Killed wherever it is: the last complete checkpoint (or the one before it, if the
  # kill came while the last was being written) must resume. The kill must come after
  # the first checkpoint: the run is retried with a longer delay until one exists.
  write_run(stop part "${_every}")
  foreach(_delay ${KILL_AFTER} 0.5 1 2 4 8)
    file(REMOVE_RECURSE ${WORK}/part)
    execute_process(COMMAND timeout -s KILL ${_delay} ${LACERTA} stop.prm
      WORKING_DIRECTORY ${WORK} RESULT_VARIABLE _result
      OUTPUT_FILE ${WORK}/stop.log ERROR_FILE ${WORK}/stop.err)
    if(EXISTS ${WORK}/part/checkpoint.lcp)
      message("killed after ${_delay} s (exit ${_result})")
      break()
    endif()
  endforeach()
else()
  write_run(stop part "${_every}  set Stop after steps = ${STOP}\n")
  run(stop TRUE)
  file(STRINGS ${WORK}/part/statistics.csv _rows)
  list(LENGTH _rows _n)
  math(EXPR _expected "${STOP} + 2")
  if(NOT _n EQUAL _expected)
    message(FATAL_ERROR "the stopped run wrote ${_n} lines of statistics.csv, not ${_expected}")
  endif()
endif()
if(NOT EXISTS ${WORK}/part/checkpoint.lcp)
  message(FATAL_ERROR "no checkpoint was written")
endif()
if(DEFINED SECONDS AND NOT EXISTS ${WORK}/part/checkpoint.lcp.previous)
  message(FATAL_ERROR "no checkpoint was written by wall time before the stop's")
endif()

if(DEFINED CHANGED_ENTRY)
  string(REPLACE "/" ";" _path "${CHANGED_ENTRY}")
  list(POP_BACK _path _entry)
  set(_lines "include scene.prm\nset Output directory = part\n")
  foreach(_subsection ${_path})
    string(APPEND _lines "subsection ${_subsection}\n")
  endforeach()
  string(APPEND _lines "set ${_entry}\n")
  foreach(_subsection ${_path})
    string(APPEND _lines "end\n")
  endforeach()
  string(APPEND _lines "subsection Checkpoint\n  set Resume = true\nend\n")
  file(WRITE ${WORK}/changed.prm "${_lines}")
  run(changed FALSE)
  file(READ ${WORK}/changed.err _err)
  if(run_result EQUAL 0 OR NOT _err MATCHES "written with other parameters")
    message(FATAL_ERROR "a resume with '${CHANGED_ENTRY}' was not refused:\n${_err}")
  endif()
  message("refused as it should be: ${_err}")
endif()

write_run(resume part "${_every}  set Resume = true\n")
run(resume TRUE)

file(GLOB _full RELATIVE ${WORK}/full ${WORK}/full/*.vtu)
file(GLOB _part RELATIVE ${WORK}/part ${WORK}/part/*.vtu)
if(NOT _full STREQUAL _part)
  message(FATAL_ERROR "VTU files differ: uninterrupted ${_full}, resumed ${_part}")
endif()
list(LENGTH _full _n_vtu)
foreach(_file statistics.csv solution.pvd ${_full})
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files
    ${WORK}/full/${_file} ${WORK}/part/${_file} RESULT_VARIABLE _different)
  if(_different)
    message(FATAL_ERROR "${_file} of the resumed run differs from the uninterrupted run's")
  endif()
endforeach()
file(STRINGS ${WORK}/resume.log _resumed REGEX "^Resumed from")
message("${_resumed}; statistics.csv, solution.pvd and ${_n_vtu} VTU files identical")
