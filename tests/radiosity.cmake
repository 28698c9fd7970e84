# radiosity.cmake - tests of the radiosity application (apps/radiosity) and of
# `vwalls radiosity`. Each runs in well under 30 s on 2 cores (RelWithDebInfo).

add_executable(test_radiosity ${PROJECT_SOURCE_DIR}/tests/radiosity/test_radiosity.c)
target_include_directories(test_radiosity PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_radiosity PRIVATE vwalls_apps m)

foreach(t ffsum parallel perpendicular box furnace twosided layouts checkpoint subdivide concave placement manycells)
  add_test(NAME radiosity_${t} COMMAND test_radiosity ${t})
  set_tests_properties(radiosity_${t} PROPERTIES LABELS "radiosity;threads" TIMEOUT 60)
endforeach()
# Label "slow": minutes under ThreadSanitizer (the solver's single-threaded rasterising
# runs 10-20x slower there), so the TSan stage of CI leaves them to the plain and ASan
# runs; the threads engine is exercised under TSan by the other threads-labelled tests.
set_tests_properties(radiosity_layouts radiosity_checkpoint radiosity_subdivide PROPERTIES
                     LABELS "radiosity;threads;slow")

# The full-matrix Gauss-Seidel reference, and the progressive solution against it.
add_test(NAME radiosity_reference COMMAND test_radiosity reference)
set_tests_properties(radiosity_reference PROPERTIES LABELS "radiosity;threads;slow" TIMEOUT 180 PROCESSORS 2)

# The command line: bad input (exit 2, file:line, no output) and kill -9 after a
# checkpoint, then --resume, against the uninterrupted run.
add_test(NAME radiosity_cli
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/radiosity/cli.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR}/tests/radiosity ${CMAKE_CURRENT_BINARY_DIR}/radiosity_cli
                 $<TARGET_FILE:test_radiosity>)
set_tests_properties(radiosity_cli PROPERTIES LABELS "radiosity;threads;slow" TIMEOUT 60)

# Under mpirun -np 2 and 4 (launcher flags: cmake/mpi_launcher.cmake): 2x2x2 and 4x4x4 with 1 and 2 workers per process against the one-cell
# threads solution (<= 1 % RMS, ledger <= 1e-9), outputs from rank 0 only, and
# --checkpoint-every / --resume under MPI.
if(VW_HAVE_MPI)
  foreach(np 2 4)
    add_test(NAME radiosity_mpi_np${np}
             COMMAND sh ${PROJECT_SOURCE_DIR}/tests/radiosity/mpi.sh ${np} $<TARGET_FILE:vwalls_tool>
                     $<TARGET_FILE:test_radiosity> ${CMAKE_CURRENT_BINARY_DIR}/radiosity_mpi_np${np}
                     ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${VW_MPI_PREFLAGS})
    set_tests_properties(radiosity_mpi_np${np} PROPERTIES LABELS "radiosity;mpi" TIMEOUT 240
                         ENVIRONMENT "${VW_MPI_ENV}" PROCESSORS 2)
  endforeach()
endif()

# The stopping rule compares patches, whatever the walls cut them into: the same share
# of the emitted power is left unshot on 1, 2x2x2 and 6x6x6 cells.
add_test(NAME radiosity_stopping
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/radiosity/stopping.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/radiosity_stopping $<TARGET_FILE:test_radiosity>)
set_tests_properties(radiosity_stopping PROPERTIES LABELS "radiosity;threads" TIMEOUT 60)

# Spheres and cones as facets, PLY without emission, mesh warnings' lines, a huge
# --patch-size, and --view on a tiny scene and near vertical.
add_test(NAME radiosity_input
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/radiosity/input.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/radiosity_input $<TARGET_FILE:test_radiosity>)
set_tests_properties(radiosity_input PROPERTIES LABELS "radiosity;threads" TIMEOUT 60)

# A closed box of Kd 1 absorbs nothing: a warning before the solve names the material's
# Kd line and the first polygon's, and the solve stops, stalled, after --stall-shots
# shots that spend less than sf (on 1, 2x2x2 and 6x6x6 cells); absorbing and open boxes
# converge as before.
add_test(NAME radiosity_closed
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/radiosity/closed.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR}/tests/radiosity ${CMAKE_CURRENT_BINARY_DIR}/radiosity_closed)
# About 60,000 shots in all (6 s here): "slow", left to the plain and ASan runs (see above).
set_tests_properties(radiosity_closed PROPERTIES LABELS "radiosity;threads;slow" TIMEOUT 120)
