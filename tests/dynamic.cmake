# dynamic.cmake - tests of the dynamic-scene handler (src/dynamic, apps/raytrace/anim.c,
# vwalls animate / edit): pairwise tests on hand-made cases; the placement rule after
# every edit of random scripts (brute force over all cells, both worlds); distributed
# batch decisions equal to the one-at-a-time O(n^2) reference; tunnelling; a frame after
# edits bit-identical to rendering the edited scene from scratch; the command line.

add_executable(test_dynamic ${PROJECT_SOURCE_DIR}/tests/dynamic/test_dynamic.c)
target_include_directories(test_dynamic PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_dynamic PRIVATE vwalls_apps m)

add_test(NAME dynamic_primitives COMMAND test_dynamic primitives)
add_test(NAME dynamic_tunnel COMMAND test_dynamic tunnel)
add_test(NAME dynamic_swept COMMAND test_dynamic swept)
foreach(w 1 2 4)
  add_test(NAME dynamic_placement_w${w} COMMAND test_dynamic placement 4 --workers ${w})
  add_test(NAME dynamic_decisions_w${w} COMMAND test_dynamic decisions 4 --workers ${w})
endforeach()
add_test(NAME dynamic_frame COMMAND test_dynamic frame 2 --workers 2)
add_test(NAME dynamic_decisions_stress COMMAND test_dynamic decisions 2 --workers 3)
set_tests_properties(dynamic_decisions_stress PROPERTIES ENVIRONMENT "VW_STRESS=42;VW_STRESS_SPLIT=1")

# The command line: summary, frames, stats; bad lines give file:line and status 2 (or
# are skipped with --keep-going), the bad scripts of tests/data/edits too; vwalls edit
# answers from stdin.
add_test(NAME dynamic_cli
  COMMAND sh ${PROJECT_SOURCE_DIR}/tests/dynamic/cli.sh $<TARGET_FILE:vwalls_tool>
          ${CMAKE_CURRENT_BINARY_DIR}/dynamic_cli ${PROJECT_SOURCE_DIR}/tests/data/edits)

# One script's decisions and frames on cells 1, 2x2x1, 4x4x4 and workers 1, 2 against the
# brute-force reference, on a scene made to stress the walls (touching across them, a
# pane lying in one, a polygon that is a segment), with hand-checked outcomes.
add_test(NAME dynamic_layouts
  COMMAND sh ${PROJECT_SOURCE_DIR}/tests/dynamic/layouts.sh $<TARGET_FILE:vwalls_tool>
          ${CMAKE_CURRENT_BINARY_DIR}/dynamic_layouts)
set_tests_properties(dynamic_layouts PROPERTIES TIMEOUT 120)

# Under mpirun -np 2 (launcher flags: cmake/mpi_launcher.cmake).
if(VW_HAVE_MPI AND MPIEXEC_EXECUTABLE)
  foreach(t placement decisions frame)
    add_test(NAME dynamic_mpi_${t}
             COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${VW_MPI_PREFLAGS}
                     $<TARGET_FILE:test_dynamic> ${t} 2 --workers 1 ${MPIEXEC_POSTFLAGS})
    set_tests_properties(dynamic_mpi_${t} PROPERTIES LABELS "mpi" TIMEOUT 180 PROCESSORS 2
                         ENVIRONMENT "${VW_MPI_ENV}")
  endforeach()
endif()

# The parser's messages show the script's words printable (binary scripts, escapes).
add_executable(test_edit_shown ${PROJECT_SOURCE_DIR}/tests/dynamic/test_edit_shown.c)
target_include_directories(test_edit_shown PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_edit_shown PRIVATE vwalls_static m)
add_test(NAME dynamic_edit_shown COMMAND test_edit_shown)
add_test(NAME dynamic_cli_shown
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/dynamic/cli_shown.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/dynamic_cli_shown)
set_tests_properties(dynamic_cli_shown PROPERTIES TIMEOUT 60)

# A frame that would replace an input (the script, the scene or a material library through
# a link) is refused before any frame; vwalls edit goes on after a frame it cannot write.
add_test(NAME dynamic_anim_inputs
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/dynamic/anim_inputs.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/dynamic_anim_inputs)
set_tests_properties(dynamic_anim_inputs PROPERTIES TIMEOUT 120)

# What animate / edit count and say: live objects in the stats (a remove drops them),
# edits apart from invalid lines, the log naming the command of a line that does not
# parse, 'balance' under --farm all.
add_test(NAME dynamic_anim_counts
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/dynamic/anim_counts.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/dynamic_anim_counts)
set_tests_properties(dynamic_anim_counts PROPERTIES TIMEOUT 120)
