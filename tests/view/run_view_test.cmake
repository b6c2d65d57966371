# Runs a test of the pictures under a virtual X display (xvfb-run):
#   MODE=viewer      lacerta-view drives SCENE with the scripted EVENTS and records the
#                    stroke; the screenshot must show the tissue, the stroke must have
#                    cut cells, and 'lacerta' on the record must end with the same mesh
#                    (tetrahedra, cells cut, components);
#   MODE=png         lacerta runs SCENE with the png postprocessor; its last picture
#                    must show the tissue;
#   MODE=benchmark   lacerta-view --benchmark on SCENE must report its figures;
#   MODE=no_display  PROGRAM on SCENE without DISPLAY must stop with exit code 1 and a
#                    message that names xvfb-run.
# Variables: MODE, SCENE, EVENTS, VIEWER, LACERTA, PROGRAM, COVERAGE (the script),
# WORK (a fresh directory).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(XVFB xvfb-run -a -s "-screen 0 1280x1024x24")

function(run_checked)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "'${ARGN}' failed (${rc}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

# "MS <tetrahedra>, CuT <mean>, ... mesh components <n>" of the cut summary.
function(summary text prefix)
  string(REGEX MATCH "MS ([0-9]+), CuT ([0-9.e+-]+)" m "${text}")
  if(NOT m)
    message(FATAL_ERROR "no cut summary in:\n${text}")
  endif()
  set(${prefix}_tets ${CMAKE_MATCH_1} PARENT_SCOPE)
  set(${prefix}_cut ${CMAKE_MATCH_2} PARENT_SCOPE)
  string(REGEX MATCH "mesh components ([0-9]+)" m "${text}")
  set(${prefix}_pieces ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()

if(MODE STREQUAL "viewer")
  run_checked(${XVFB} ${VIEWER} --size 800x600 --record stroke_record.prm
    --events ${EVENTS} ${SCENE})
  summary("${out}" view)
  message(STATUS "lacerta-view: ${view_tets} tetrahedra, ${view_cut} cut per cutting step, ${view_pieces} components")
  if(view_cut EQUAL 0)
    message(FATAL_ERROR "the stroke cut nothing:\n${out}")
  endif()
  run_checked(python3 ${COVERAGE} stroke.png 0.05 0.9)
  message(STATUS "${out}")
  run_checked(${LACERTA} stroke_record.prm)
  summary("${out}" replay)
  message(STATUS "replay: ${replay_tets} tetrahedra, ${replay_cut} cut per cutting step, ${replay_pieces} components")
  if(NOT view_tets EQUAL replay_tets OR NOT view_cut STREQUAL replay_cut
     OR NOT view_pieces EQUAL replay_pieces)
    message(FATAL_ERROR "the recorded stroke does not replay to the same mesh")
  endif()
elseif(MODE STREQUAL "benchmark")
  # The figures depend on the machine; the run must reach the end of its stroke and
  # report them.
  run_checked(${XVFB} ${VIEWER} --size 800x600 --benchmark ${SCENE})
  string(REGEX MATCH "Benchmark stroke[^\n]*real-time factor ([0-9.e+-]+)[^\n]* ([0-9.e+-]+) frames per second" m "${out}")
  if(NOT m)
    message(FATAL_ERROR "no benchmark figures in:\n${out}")
  endif()
  message(STATUS "${m}")
elseif(MODE STREQUAL "png")
  run_checked(${XVFB} ${LACERTA} ${SCENE})
  file(GLOB pictures ${WORK}/output/png/picture-*.png)
  list(LENGTH pictures n)
  if(n LESS 3)
    message(FATAL_ERROR "expected 3 pictures, found ${n}")
  endif()
  list(SORT pictures)
  list(GET pictures -1 last)
  run_checked(python3 ${COVERAGE} ${last} 0.05 0.9)
  message(STATUS "${out}")
elseif(MODE STREQUAL "no_display")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${PROGRAM} ${SCENE}
    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
    TIMEOUT 300)
  if(NOT rc EQUAL 1 OR NOT err MATCHES "needs an X display.*xvfb-run -a")
    message(FATAL_ERROR "expected exit code 1 and a message naming xvfb-run, got ${rc}:\n${err}")
  endif()
else()
  message(FATAL_ERROR "unknown MODE '${MODE}'")
endif()
