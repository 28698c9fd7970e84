# examples.cmake - tests of the second example module (examples/components.c): the
# distributed components equal the sequential reference, label for label, for every
# layout and worker count, under the stress switches, and under mpirun when MPI is found.
# (The first example, pairs, is tested in core.cmake and mpi.cmake; both examples against
# a brute force on sphere sets made to stress them, their command line and vwalls bench's
# rays check at the end of this file.)

set(VW_EX_ARGS --spheres 3000 --radius 0.05 --seed 5 --check --quiet)
foreach(layout 1 2x4 2x2x2 4x4x4)
  foreach(workers 1 2 4)
    add_test(NAME example_components_${layout}_w${workers}
             COMMAND vwalls_tool example-components ${VW_EX_ARGS} --cells ${layout} --workers ${workers})
    set_tests_properties(example_components_${layout}_w${workers} PROPERTIES LABELS "examples;threads")
  endforeach()
endforeach()
# Delayed and reordered delivery, one message per packet: labels may arrive in any order.
add_test(NAME example_components_stress
         COMMAND vwalls_tool example-components ${VW_EX_ARGS} --cells 4x4x4 --workers 4)
set_tests_properties(example_components_stress PROPERTIES LABELS "examples;threads"
                     ENVIRONMENT "VW_STRESS=99")
add_test(NAME example_components_stress_split
         COMMAND vwalls_tool example-components ${VW_EX_ARGS} --cells 2x2x2 --workers 2)
set_tests_properties(example_components_stress_split PROPERTIES LABELS "examples;threads"
                     ENVIRONMENT "VW_STRESS=7;VW_STRESS_SPLIT=1")
# Sparse (almost no touching) and dense (one component) scenes, and no spheres at all.
add_test(NAME example_components_sparse
         COMMAND vwalls_tool example-components --spheres 2000 --radius 0.005 --cells 2x2x2 --check --quiet)
add_test(NAME example_components_dense
         COMMAND vwalls_tool example-components --spheres 2000 --radius 0.2 --cells 4x4x4 --check --quiet)
set_tests_properties(example_components_dense PROPERTIES PASS_REGULAR_EXPRESSION "^1\n")
add_test(NAME example_components_empty
         COMMAND vwalls_tool example-components --spheres 0 --cells 2x2x2 --check --quiet)
set_tests_properties(example_components_empty PROPERTIES PASS_REGULAR_EXPRESSION "^0\n")
set_tests_properties(example_components_sparse example_components_dense example_components_empty
                     PROPERTIES LABELS "examples;threads")

# Bad usage: exit status 2 (WILL_FAIL only knows non-zero, so check the 2 by script).
foreach(bad "--cells;2x" "--radius;0" "--radius;1" "--workers;0" "--bogus")
  string(REPLACE ";" "_" tname "${bad}")
  string(REGEX REPLACE "[^A-Za-z0-9_]" "" tname "${tname}")
  add_test(NAME example_components_bad_${tname}
           COMMAND sh -c "\"$0\" example-components \"$@\"; test $? -eq 2" $<TARGET_FILE:vwalls_tool> ${bad})
  set_tests_properties(example_components_bad_${tname} PROPERTIES LABELS "examples")
endforeach()

# Under mpirun: cells spread over processes, labels cross process boundaries.
if(VW_HAVE_MPI)
  set(_vw_ex_env "${VW_MPI_ENV};OMPI_MCA_rmaps_base_oversubscribe=1")
  foreach(np 2 3)
    foreach(w 1 2)
      add_test(NAME example_components_mpi_np${np}_w${w}
               COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${MPIEXEC_PREFLAGS}
                       $<TARGET_FILE:vwalls_tool> example-components ${VW_EX_ARGS} --cells 4x4x2
                       --workers ${w} ${MPIEXEC_POSTFLAGS})
      set_tests_properties(example_components_mpi_np${np}_w${w} PROPERTIES LABELS "examples;mpi"
                           TIMEOUT 120 PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
    endforeach()
  endforeach()
  add_test(NAME example_components_mpi_stress_np2
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:vwalls_tool> example-components ${VW_EX_ARGS} --cells 4x4x4
                   --workers 2 ${MPIEXEC_POSTFLAGS})
  set_tests_properties(example_components_mpi_stress_np2 PROPERTIES LABELS "examples;mpi"
                       TIMEOUT 120 PROCESSORS 2 ENVIRONMENT "${_vw_ex_env};VW_STRESS=5")
endif()

# The tutorial's code (docs/tutorial/): built against the shared library, as a user's
# program would be, and run alone, with stress, and under mpirun. Every run checks the
# counts against a sequential reference and that each cell reported exactly once (its
# neighbours' counts may all arrive before its own step: the module must not report
# twice).
add_executable(tutorial_hello_cells ${PROJECT_SOURCE_DIR}/docs/tutorial/hello_cells.c
                                    ${PROJECT_SOURCE_DIR}/docs/tutorial/hello_module.c)
target_link_libraries(tutorial_hello_cells PRIVATE vwalls::vwalls)
foreach(layout 1 2x2x2 4x4x2)
  foreach(workers 1 3)
    add_test(NAME tutorial_hello_${layout}_w${workers}
             COMMAND tutorial_hello_cells --points 20000 --cells ${layout} --workers ${workers})
    set_tests_properties(tutorial_hello_${layout}_w${workers} PROPERTIES LABELS "examples;threads"
                         PASS_REGULAR_EXPRESSION "\nok\n")
  endforeach()
endforeach()
add_test(NAME tutorial_hello_stress COMMAND tutorial_hello_cells --points 20000 --cells 4x4x4 --workers 4)
set_tests_properties(tutorial_hello_stress PROPERTIES LABELS "examples;threads"
                     ENVIRONMENT "VW_STRESS=3;VW_STRESS_SPLIT=1" PASS_REGULAR_EXPRESSION "\nok\n")
# Its command line: a mistyped or incomplete option is a usage error (exit 2), not a run
# with the defaults; a world vw_world_create refuses is reported with its reason
# (vw_world_errmsg(NULL)), not with the bare status message.
foreach(bad "--cell;4x4x4" "--workers" "--points;12x" "--workers;-3")
  string(REGEX REPLACE "[^A-Za-z0-9]+" "_" tname "${bad}")
  add_test(NAME tutorial_hello_bad${tname}
           COMMAND sh -c "\"$0\" \"$@\"; test $? -eq 2" $<TARGET_FILE:tutorial_hello_cells> ${bad})
  set_tests_properties(tutorial_hello_bad${tname} PROPERTIES LABELS "examples")
endforeach()
add_test(NAME tutorial_hello_create_errmsg
         COMMAND sh -c "out=$(\"$0\" --workers 5000 2>&1); rc=$?; echo \"$out\"; test $rc -eq 1 && echo \"$out\" | grep -q '5000 workers (at most 1024)'"
                 $<TARGET_FILE:tutorial_hello_cells>)
set_tests_properties(tutorial_hello_create_errmsg PROPERTIES LABELS "examples")
# Memory it lacks for its points is named, not a silent exit (tests/examples/hello_nomem.sh).
add_test(NAME tutorial_hello_nomem
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/examples/hello_nomem.sh $<TARGET_FILE:tutorial_hello_cells>)
set_tests_properties(tutorial_hello_nomem PROPERTIES LABELS "examples" SKIP_RETURN_CODE 77)
if(VW_HAVE_MPI)
  add_test(NAME tutorial_hello_mpi_np2
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:tutorial_hello_cells> --points 20000 --cells 4x2x2 --workers 2
                   ${MPIEXEC_POSTFLAGS})
  add_executable(tutorial_own_mpi ${PROJECT_SOURCE_DIR}/docs/tutorial/own_mpi.c
                                  ${PROJECT_SOURCE_DIR}/docs/tutorial/hello_module.c)
  target_link_libraries(tutorial_own_mpi PRIVATE vwalls::vwalls)   # MPI::MPI_C comes with it
  foreach(np 2 4)
    add_test(NAME tutorial_own_mpi_np${np}
             COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${MPIEXEC_PREFLAGS}
                     $<TARGET_FILE:tutorial_own_mpi> ${MPIEXEC_POSTFLAGS})
  endforeach()
  set_tests_properties(tutorial_hello_mpi_np2 tutorial_own_mpi_np2 tutorial_own_mpi_np4 PROPERTIES
                       LABELS "examples;mpi" TIMEOUT 120 PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
endif()

# Both example modules against an O(n^2) reference written in the test itself, on sphere
# sets made to stress them (tests/examples/test_example_spheres.c): uniform, clustered,
# exactly touching across a wall, larger than a cell, duplicated, zero radii, all radii
# zero, a world below the origin, centres on the world's faces; on the layouts 1, 2,
# 2x2x2, 4x4x4 and 1x1x8 with 1, 2 and 4 workers, also under mpirun; and sphere sets the
# modules cannot count (a radius above rmax, a centre outside the world, an id twice, ...)
# refused with VW_E_INVAL rather than counted wrong, ex_errmsg saying why ("invalid").
add_executable(test_example_spheres ${PROJECT_SOURCE_DIR}/tests/examples/test_example_spheres.c)
target_link_libraries(test_example_spheres PRIVATE vwalls_apps m)
foreach(case uniform clustered walls chains large duplicates zero allzero negative faces invalid)
  add_test(NAME example_spheres_${case} COMMAND test_example_spheres --case ${case})
  set_tests_properties(example_spheres_${case} PROPERTIES LABELS "examples;threads" TIMEOUT 300)
endforeach()
add_test(NAME example_spheres_stress
         COMMAND test_example_spheres --case walls --cells 2x2x2,4x4x4 --workers 4)
set_tests_properties(example_spheres_stress PROPERTIES LABELS "examples;threads" TIMEOUT 300
                     ENVIRONMENT "VW_STRESS=11;VW_STRESS_SPLIT=1")
if(VW_HAVE_MPI)
  foreach(np 2 3)
    add_test(NAME example_spheres_mpi_np${np}
             COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${MPIEXEC_PREFLAGS}
                     $<TARGET_FILE:test_example_spheres> --cells 2,2x2x2,4x4x4,1x1x8 --workers 1,2
                     ${MPIEXEC_POSTFLAGS})
    set_tests_properties(example_spheres_mpi_np${np} PROPERTIES LABELS "examples;mpi" TIMEOUT 300
                         PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
  endforeach()
  # A --check that fails is the output process's verdict alone: every process must exit
  # with it (1), each rank's status read from a file its own shell writes
  # (tests/examples/check_ranks.sh).
  foreach(np 2 3)
    add_test(NAME example_check_ranks_np${np}
             COMMAND sh ${PROJECT_SOURCE_DIR}/tests/examples/check_ranks.sh $<TARGET_FILE:vwalls_tool>
                     ${np} "${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${VW_MPI_PREFLAGS}")
    set_tests_properties(example_check_ranks_np${np} PROPERTIES LABELS "examples;mpi" TIMEOUT 240
                         PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
  endforeach()
  add_test(NAME example_spheres_invalid_mpi_np3
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 3 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:test_example_spheres> --case invalid --workers 1,2 ${MPIEXEC_POSTFLAGS})
  set_tests_properties(example_spheres_invalid_mpi_np3 PROPERTIES LABELS "examples;mpi" TIMEOUT 120
                       PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
endif()

# The example commands' command line (tests/examples/cli.sh): help, stdout and stderr,
# bad options, the stats, a failed --check leaving no stats.
add_test(NAME example_cli
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/examples/cli.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/example_cli)
set_tests_properties(example_cli PROPERTIES LABELS "examples" TIMEOUT 120)
# vwalls bench checks that every configuration traced the same rays (tests/examples/bench.sh).
add_test(NAME example_bench_rays
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/examples/bench.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/example_bench_rays)
set_tests_properties(example_bench_rays PROPERTIES LABELS "examples" TIMEOUT 240)
if(VW_HAVE_MPI)
  add_test(NAME example_bench_rays_mpi
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/examples/bench.sh $<TARGET_FILE:vwalls_tool>
                   ${CMAKE_CURRENT_BINARY_DIR}/example_bench_rays_mpi
                   "${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${VW_MPI_PREFLAGS}")
  set_tests_properties(example_bench_rays_mpi PROPERTIES LABELS "examples;mpi" TIMEOUT 240
                       PROCESSORS 2 ENVIRONMENT "${_vw_ex_env}")
endif()
