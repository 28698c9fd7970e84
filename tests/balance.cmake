# balance.cmake - tests of the load balancers (src/balance) and the mappers (src/map):
# images bit-identical with every strategy and mapping, objects conserved by migration,
# staggered reaching lambda <= 1.10 and divide <= 1.06 (16 cells, clustered) on deterministic
# work, rotation following the load, cells a few doubles wide (balance_thin; divide
# cutting the sides that can be cut there, balance_divide_thin; going on past a cell that
# cannot be cut, balance_divide_hot),
# and the mapping invariants. Deterministic work counts only: no timings are asserted.

add_executable(vw_test_balance ${PROJECT_SOURCE_DIR}/tests/balance/bal_test.c)
target_link_libraries(vw_test_balance PRIVATE vwalls_apps)
# (the duplication planner is tested on its own: src/balance/balance_internal.h)
target_include_directories(vw_test_balance PRIVATE ${PROJECT_SOURCE_DIR}/src)

set(VW_BAL_TSAN "TSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/raytrace/tsan.supp")
add_test(NAME balance_identical_spheres COMMAND vw_test_balance identical spheres:0.5:2 48x48)
add_test(NAME balance_identical_mixed
         COMMAND vw_test_balance identical ${PROJECT_SOURCE_DIR}/tests/raytrace/mixed.nff 48x48)
add_test(NAME balance_conserve COMMAND vw_test_balance conserve)
add_test(NAME balance_staggered8 COMMAND vw_test_balance staggered8)
add_test(NAME balance_rotate COMMAND vw_test_balance rotate)
add_test(NAME balance_divide16 COMMAND vw_test_balance divide16)
add_test(NAME balance_map COMMAND vw_test_balance map)
add_test(NAME balance_duplicate COMMAND vw_test_balance duplicate)
add_test(NAME balance_field COMMAND vw_test_balance field)
add_test(NAME balance_concurrent COMMAND vw_test_balance concurrent)
add_test(NAME balance_thin COMMAND vw_test_balance thin)
add_test(NAME balance_divide_thin COMMAND vw_test_balance divide_thin)
add_test(NAME balance_divide_hot COMMAND vw_test_balance divide_hot)
set_tests_properties(balance_identical_spheres balance_identical_mixed balance_conserve
  balance_staggered8 balance_divide16 balance_rotate balance_map balance_duplicate
  balance_field balance_concurrent balance_thin balance_divide_thin balance_divide_hot PROPERTIES LABELS "balance;threads"
  ENVIRONMENT "${VW_BAL_TSAN}")

# The command line: PNG bytes equal for every --balance and --map, under the threads
# engine and (when the build has MPI) under mpirun -np 2.
set(_vw_bal_mpi "")
if(VW_HAVE_MPI AND MPIEXEC_EXECUTABLE)
  string(REPLACE ";" "|" _vw_bal_pre "${VW_MPI_PREFLAGS}")
  set(_vw_bal_mpi -DMPIRUN=${MPIEXEC_EXECUTABLE} -DNPFLAG=${MPIEXEC_NUMPROC_FLAG}
      "-DPREFLAGS=${_vw_bal_pre}")
endif()
add_test(NAME balance_cli
  COMMAND ${CMAKE_COMMAND} -DVWALLS=$<TARGET_FILE:vwalls_tool>
          -DSCENE=${PROJECT_SOURCE_DIR}/tests/raytrace/mixed.nff
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/balance_cli ${_vw_bal_mpi}
          -P ${PROJECT_SOURCE_DIR}/tests/balance/cli.cmake)
set_tests_properties(balance_cli PROPERTIES LABELS "balance;mpi" TIMEOUT 300 PROCESSORS 2
  ENVIRONMENT "${VW_MPI_ENV};${VW_BAL_TSAN}")

# divide stops when an uncuttable cell alone sets lambda on a fastest worker (no cut can
# lower it), and goes on where, with speeds or company on its worker, cuts still can.
add_test(NAME balance_divide_stop COMMAND vw_test_balance divide_stop)
set_tests_properties(balance_divide_stop PROPERTIES LABELS "balance")

# divide's bound on extra cells holds over a run of divides, each on the last one's result
# (render's rounds, animate's rebalances), not per call: the cells piled up round after
# round (1026 at 4x4x4 on 64 workers for a bound of 64 + 4 x 64).
add_test(NAME balance_divide_rounds COMMAND vw_test_balance divide_rounds)
add_test(NAME balance_divide_rounds_render COMMAND vw_test_balance divide_rounds_render)
set_tests_properties(balance_divide_rounds balance_divide_rounds_render PROPERTIES
  LABELS "balance;threads" ENVIRONMENT "${VW_BAL_TSAN}")

# A balance the render keeps never gives its slowest worker more counted work than the
# layout it started from (rotate and divide lowered lambda while adding work).
add_test(NAME balance_slowest
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/balance/slowest.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/balance_slowest)
set_tests_properties(balance_slowest PROPERTIES LABELS "balance" TIMEOUT 120)

# Tensor and staggered cut each cell at its worker's share of the load where the mapping
# gives the workers unequal numbers of cells (3 on 2 workers, 4 on 3): equal cells left
# lambda at 4/3 and 3/2 whatever the load.
add_test(NAME balance_shares COMMAND vw_test_balance shares)
set_tests_properties(balance_shares PROPERTIES LABELS "balance;threads" ENVIRONMENT "${VW_BAL_TSAN}")


# What the rounds keep and what the experiments' table reads of it (counted work): rotate
# ended on the grid, unbalanced, when its rotated frame was refuted and could not be
# re-cut; a kept starting layout reports predicted = before; bench/experiments/stats.awk's
# work lambda counts a duplicated or farmed cell's work where its copies ran.
add_test(NAME balance_kept
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/balance/kept.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/balance_kept)
set_tests_properties(balance_kept PROPERTIES LABELS "balance" TIMEOUT 120)
