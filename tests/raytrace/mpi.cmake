# mpi.cmake (raytrace) - `vwalls render` under mpirun with 2 and 3 processes, with and
# without farming, must write the very PNG bytes the threads engine writes; the files are
# written by rank 0 only. Variables: VWALLS, SCENE, WORK, MPIRUN, NPFLAG, PREFLAGS
# (PREFLAGS with '|' between flags).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
string(REPLACE "|" ";" pre "${PREFLAGS}")
execute_process(COMMAND ${VWALLS} render ${SCENE} -o ${WORK}/ref.png --size 80x60 --quiet
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "threads engine: exit ${rc}: ${err}")
endif()
# np; cells; workers; farm (copies of cells: none, on idle workers and processes
# (1 cell on 2 processes), on every worker)
foreach(case "2;2x2x2;1;none" "2;4x1x2;2;none" "3;2x2;1;none" "2;1;1;idle" "3;1;2;idle"
             "2;2x2x2;2;all")
  list(GET case 0 np)
  list(GET case 1 cells)
  list(GET case 2 workers)
  list(GET case 3 farm)
  set(out ${WORK}/np${np}_${cells}_${workers}_${farm}.png)
  execute_process(COMMAND ${MPIRUN} ${NPFLAG} ${np} ${pre} ${VWALLS} render ${SCENE} -o ${out}
                          --size 80x60 --cells ${cells} --workers ${workers} --farm ${farm}
                          --quiet --stats ${WORK}/np${np}.json
                  RESULT_VARIABLE rc ERROR_VARIABLE err TIMEOUT 60)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "mpirun -np ${np} --cells ${cells}: exit ${rc}: ${err}")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/ref.png ${out}
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "mpirun -np ${np} --cells ${cells} --workers ${workers} --farm ${farm}: "
                        "PNG differs")
  endif()
  file(READ ${WORK}/np${np}.json json)
  string(FIND "${json}" "\"processes\": ${np}" at)
  if(at LESS 0)
    message(FATAL_ERROR "stats JSON does not say ${np} processes")
  endif()
endforeach()
message(STATUS "raytrace_mpi: identical to the threads engine")
