# experiments.cmake - the smoke version of bench/experiments.sh (the paper's evaluation):
# tiny sphere scenes and the Cornell box on two layouts, threads engine and (when mpirun
# works) MPI, balancing rows when the build has --balance. It checks the shape and sanity
# of the CSV (bench/experiments/check.awk: the expected columns, speedup > 0 and equal to
# the fastest sequential time over the row's, efficiency = speedup / workers, lambda >= 1),
# never a timing: an efficiency bound failed here under a doubled load. Needs bash and
# awk only: the smoke run skips POV-Ray, gnuplot and python3. Label "bench".

set(VW_EXP_DIR ${PROJECT_SOURCE_DIR}/bench/experiments)
add_test(NAME experiments_smoke
  COMMAND sh -c "bash \"$0\" --smoke --out \"$1\" --build \"$2\" >\"$1.log\" 2>&1 || { cat \"$1.log\"; exit 1; }; cat \"$1.log\"; awk -F, -f \"$3\" \"$1/results.csv\""
          ${PROJECT_SOURCE_DIR}/bench/experiments.sh ${CMAKE_CURRENT_BINARY_DIR}/experiments_smoke
          $<TARGET_FILE_DIR:vwalls_tool> ${VW_EXP_DIR}/check.awk)
set_tests_properties(experiments_smoke PROPERTIES LABELS "bench;mpi" TIMEOUT 120 PROCESSORS 2
  ENVIRONMENT "${VW_MPI_ENV}")

# The checker itself: it must accept a good CSV and reject each deliberately bad one.
add_test(NAME experiments_checker
  COMMAND sh ${PROJECT_SOURCE_DIR}/tests/experiments/checker.sh ${VW_EXP_DIR}/check.awk
          ${PROJECT_SOURCE_DIR}/tests/experiments)
set_tests_properties(experiments_checker PROPERTIES LABELS "bench")
