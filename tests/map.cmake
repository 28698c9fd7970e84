# map.cmake - the mappers of cells onto workers and processes (src/map): block leaving no
# worker without a cell when the grid has enough (and none over what runs of cells give),
# greedy placing by the loads it sorts whatever they are (NaN, negative, none at all),
# and the command line under mpirun giving every worker of 3 processes of 3 a cell of
# 2x5x1 with --map block (worker 8 had none) with the image unchanged; and render's
# default mapping being block's, as its stats say. block_area: block cuts the least wall
# area, from the grid's walls (by faces alone 2x2x2 of a flat world was cut at its broad
# horizontal wall); dims: vw_map_dims refuses n < 1 (it gave {0, 1, 1}); greedy_inf:
# cells of infinite load spread one to a worker first (all went to worker 0).

add_executable(vw_test_map ${PROJECT_SOURCE_DIR}/tests/map/map_test.c)
target_include_directories(vw_test_map PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(vw_test_map PRIVATE vwalls_static m)
foreach(t block greedy_nan greedy_zero block_area dims greedy_inf)
  add_test(NAME map_${t} COMMAND vw_test_map ${t})
  set_tests_properties(map_${t} PROPERTIES LABELS "map" TIMEOUT 60)
endforeach()

add_test(NAME map_default_block
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/map/default_block.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/map_default_block)
set_tests_properties(map_default_block PROPERTIES LABELS "map;threads" TIMEOUT 60)

if(VW_HAVE_MPI AND MPIEXEC_EXECUTABLE)
  add_test(NAME map_block_mpi
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/map/every_worker.sh $<TARGET_FILE:vwalls_tool>
                   ${CMAKE_CURRENT_BINARY_DIR}/map_block_mpi
                   "${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 3 ${VW_MPI_PREFLAGS}")
  set_tests_properties(map_block_mpi PROPERTIES LABELS "map;mpi" TIMEOUT 120 PROCESSORS 2
                       ENVIRONMENT "${VW_MPI_ENV};OMPI_MCA_rmaps_base_oversubscribe=1")
endif()
