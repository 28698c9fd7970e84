# mpi.cmake - tests of the MPI engine (only when the build found MPI): the example module
# and a message storm under np 1, 2, 4, 8 with 1 and 2 workers per process, giving the
# threads engine's results, also under the stress switches; agreement between ranks;
# a rank that dies or exits mid-run (the job must end within 10 s with a message naming
# it); and two "machines" in network namespaces. Label "mpi".

if(NOT VW_HAVE_MPI)
  return()
endif()

# The launcher flags (VW_MPI_PREFLAGS, VW_MPI_FLAVOUR, VW_MPI_ENV): cmake/mpi_launcher.cmake.

# The storm and its agreement, fault and failure modes: tests/core/test_storm.c, the
# threads engine's storm test (core.cmake), run by every rank of a job here.

# vw_mpi_test(NAME NP [ENV list] COMMAND args...)
function(vw_mpi_test name np)
  cmake_parse_arguments(A "" "" "ENV;COMMAND" ${ARGN})
  add_test(NAME ${name}
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${VW_MPI_PREFLAGS}
                   ${A_COMMAND} ${MPIEXEC_POSTFLAGS})
  set_tests_properties(${name} PROPERTIES LABELS "mpi" TIMEOUT 120
                       ENVIRONMENT "${VW_MPI_ENV};${A_ENV}" PROCESSORS 2)
endfunction()

# vw_mpi_script_test(NAME NP SCRIPT TIMEOUT args...): sh tests/mpi/SCRIPT args... with the
# launch command ("mpirun -np NP flags", one word) last; the script starts the job itself.
function(vw_mpi_script_test name np script timeout)
  add_test(NAME ${name}
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/mpi/${script} ${ARGN}
                   "${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${VW_MPI_PREFLAGS}")
  set_tests_properties(${name} PROPERTIES LABELS "mpi" TIMEOUT ${timeout}
                       ENVIRONMENT "${VW_MPI_ENV}" PROCESSORS 2)
endfunction()

foreach(np 1 2 4 8)
  foreach(w 1 2)
    vw_mpi_test(mpi_storm_np${np}_w${w} ${np} COMMAND $<TARGET_FILE:test_storm> --workers ${w} --seeds 2)
    vw_mpi_test(mpi_pairs_np${np}_w${w} ${np}
                COMMAND $<TARGET_FILE:vwalls_tool> example-pairs --spheres 3000 --radius 0.03 --seed 5
                        --cells 4x4x2 --workers ${w} --check --quiet)
  endforeach()
endforeach()
foreach(np 2 4 8)
  vw_mpi_test(mpi_storm_stress_np${np} ${np} ENV "VW_STRESS=${np}"
              COMMAND $<TARGET_FILE:test_storm> --workers 2 --seeds 2)
  vw_mpi_test(mpi_storm_split_np${np} ${np} ENV "VW_STRESS=1${np};VW_STRESS_SPLIT=1"
              COMMAND $<TARGET_FILE:test_storm> --workers 1 --seeds 1)
endforeach()
vw_mpi_test(mpi_pairs_stress_np4 4 ENV "VW_STRESS=99"
            COMMAND $<TARGET_FILE:vwalls_tool> example-pairs --spheres 3000 --radius 0.03 --cells 4x4x4
                    --workers 2 --check --quiet)
# The storm as the threads engine's tests run it (1 to 8 workers per process, varying).
vw_mpi_test(mpi_core_storm_np3 3 COMMAND $<TARGET_FILE:test_storm> 2)
# A step() that sends and reports no work: what it sent arrives in that run, across
# processes too.
if(TARGET test_runtime)
  vw_mpi_test(mpi_runtime_step_send_np2 2 COMMAND $<TARGET_FILE:test_runtime> step-send)
  vw_mpi_test(mpi_runtime_step_send_np3 3 ENV "VW_STRESS=7" COMMAND $<TARGET_FILE:test_runtime> step-send)
endif()
# Farmed work across processes: a copy that is done takes the turns of copies in other
# processes (every batch once; the slowed processes' turns go to the fast one).
if(TARGET test_farm)
  vw_mpi_test(mpi_farm_np2 2 COMMAND $<TARGET_FILE:test_farm> --mpi)
  vw_mpi_test(mpi_farm_stress_np3 3 ENV "VW_STRESS=3" COMMAND $<TARGET_FILE:test_farm> --mpi --stress)
  # A turn request naming a copy the receiver does not host ends the job, saying so.
  vw_mpi_script_test(mpi_turn_check 2 must_say.sh 60 turn
                     "asked for turns of cell 0, copy [0-9]+, which this process does not host"
                     $<TARGET_FILE:test_farm> --mpi --garble-turn)
endif()
vw_mpi_test(mpi_agree_np1 1 COMMAND $<TARGET_FILE:test_storm> --agree)
vw_mpi_test(mpi_agree_np3 3 COMMAND $<TARGET_FILE:test_storm> --agree)

# Counters and per-cell messages of the stats JSON equal the threads engine's.
set(VW_MPI_LAUNCH ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG})
foreach(np 2 4)
  vw_mpi_script_test(mpi_pairs_same_stats_np${np} ${np} same_stats.sh 120 $<TARGET_FILE:vwalls_tool>)
endforeach()

# Only the first process prints: stdout under mpirun equals the single process's.
vw_mpi_script_test(mpi_print_once 3 print_once.sh 120
                   $<TARGET_FILE:vwalls_tool> ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff)

# Input only some ranks have (stdin of vwalls edit, a file missing on one host) and
# outputs only rank 0 writes: no rank is left waiting.
vw_mpi_script_test(mpi_rank_input 2 rank_input.sh 240
                   $<TARGET_FILE:vwalls_tool> ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff)

# vwalls radiosity --resume reads the checkpoint on rank 0 alone, which wrote it, and
# hands it to the others: it resumes where only rank 0's host has the file, and another
# host's stale copy changes nothing.
foreach(np 2 3)
  vw_mpi_script_test(mpi_resume_rank0_np${np} ${np} resume_rank0.sh 240 $<TARGET_FILE:vwalls_tool>)
endforeach()

# The default worker count: processes of one host that may run on the same CPUs share
# its cores (two unbound processes: half each, as their affinity masks overlap).
vw_mpi_script_test(mpi_core_share 2 core_share.sh 120
                   $<TARGET_FILE:vwalls_tool> ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff
                   ${VW_MPI_FLAVOUR})

# A check one rank alone fails (its own copy of the scene, its memory) stops every rank.
vw_mpi_script_test(mpi_rank_alone 2 rank_alone.sh 150
                   $<TARGET_FILE:vwalls_tool> ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff)

# Faults: the job ends within 10 s, non-zero, naming the rank (a rank that hangs: by the
# launcher's time limit, MPIEXEC_TIMEOUT).
foreach(mode kill exit hang)
  vw_mpi_script_test(mpi_fault_${mode} 4 fault.sh 60 ${mode} $<TARGET_FILE:test_storm>)
endforeach()

# Two machines: network namespaces joined by a veth pair, TCP only (Open MPI's rsh
# launcher into the namespaces). Skipped where namespaces cannot be made.
if(VW_MPI_FLAVOUR STREQUAL "openmpi")
  add_test(NAME mpi_two_hosts
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/mpi/two_hosts.sh $<TARGET_FILE:vwalls_tool>
                   ${MPIEXEC_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff)
  set_tests_properties(mpi_two_hosts PROPERTIES LABELS "mpi" TIMEOUT 180 SKIP_RETURN_CODE 77
                       ENVIRONMENT "${VW_MPI_ENV}" RUN_SERIAL TRUE)
endif()

# A step of a world's life that fails on one rank only (a bad speed at create, out of
# memory adding objects, an unknown object, a bad copy or mapping, cell_build failing on
# that rank's cells at commit or in run's commit, named: "rank 1: building cell 2 failed"):
# every rank fails that step with the failing rank's message and exits, none waits for
# the others. So does a run that a handler fails on one rank (vw_ctx_fail) while every
# step() sends for ever: every rank drops its work from the next wave on.
foreach(step create add update replicas redecompose commit run handler)
  vw_mpi_script_test(mpi_local_fail_${step} 3 local_fail.sh 60 ${step} 3 $<TARGET_FILE:test_storm>)
endforeach()

# A run that fails on the output process alone (an output only rank 0 writes, in every
# command; vwalls radiosity's energy ledger, which rank 0 checks): every rank exits with
# its status, 1, not 0 on the others, and the message comes once.
foreach(np 2 3)
  vw_mpi_script_test(mpi_rank_status_np${np} ${np} rank_status.sh 300
                     $<TARGET_FILE:vwalls_tool> ${np})
endforeach()

# A process that runs another build of the program (VW_FAULT=build-id gives each its own
# build ID): the world is not made, and says which process; VW_MIXED_BUILDS=1 lets it run.
vw_mpi_script_test(mpi_build_check 2 must_say.sh 60 build
                   "process 1 runs another build of this program than process 0"
                   env VW_FAULT=build-id $<TARGET_FILE:vwalls_tool> example-pairs --spheres 300
                   --cells 2x2x1 --quiet)
vw_mpi_test(mpi_build_mixed 2 ENV "VW_FAULT=build-id;VW_MIXED_BUILDS=1"
            COMMAND $<TARGET_FILE:vwalls_tool> example-pairs --spheres 300 --cells 2x2x1 --check --quiet)
# A peer whose module has a message kind more (another build): the receiver checks every
# packet from another process and stops the job, naming the sender.
vw_mpi_script_test(mpi_wire_check 2 must_say.sh 60 wire
                   "rank 0: packet from rank 1 .*malformed: message 0 is of kind 3"
                   $<TARGET_FILE:test_storm> --wire)
# A step() that calls vw_world_agree (a collective, from a worker thread mid-run) stops
# the job naming the call, as the calls that change the world from a callback do.
vw_mpi_script_test(mpi_agree_in_step 2 must_say.sh 60 agree-in-step
                   "called vw_world_agree from a callback during a run"
                   $<TARGET_FILE:test_storm> --agree-in-step)

# vw_world_traffic and vw_world_machines given a NULL pointer on some ranks only: every
# rank fails with the lowest failing rank's message, none waits for the others (a hang
# is caught by the time limit); alone, the threads engine's plain message.
add_executable(test_mpi_traffic_agree ${PROJECT_SOURCE_DIR}/tests/mpi/test_mpi_traffic_agree.c)
target_include_directories(test_mpi_traffic_agree PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_mpi_traffic_agree PRIVATE vwalls_static m)
foreach(np 1 2 3)
  vw_mpi_test(mpi_traffic_agree_np${np} ${np} COMMAND $<TARGET_FILE:test_mpi_traffic_agree>)
  set_tests_properties(mpi_traffic_agree_np${np} PROPERTIES TIMEOUT 60)
endforeach()
add_test(NAME traffic_agree_threads COMMAND test_mpi_traffic_agree)
set_tests_properties(traffic_agree_threads PROPERTIES LABELS "mpi" TIMEOUT 60)

# The object records under MPI: each process keeps only its cells' and copies' share,
# and every cell gets its records whole through remaps, new decompositions, copies and
# moves (records fetched from the processes that keep them). Alone: every record kept.
add_executable(test_mpi_records ${PROJECT_SOURCE_DIR}/tests/mpi/test_mpi_records.c)
target_include_directories(test_mpi_records PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/src)
target_link_libraries(test_mpi_records PRIVATE vwalls_static m)
foreach(np 2 3 4)
  vw_mpi_test(mpi_records_np${np} ${np} COMMAND $<TARGET_FILE:test_mpi_records>)
endforeach()
vw_mpi_test(mpi_records_np2_w2 2 ENV "VW_STRESS=7" COMMAND $<TARGET_FILE:test_mpi_records> --workers 2)
add_test(NAME records_threads COMMAND test_mpi_records --workers 2)
set_tests_properties(records_threads PROPERTIES LABELS "mpi" TIMEOUT 60)
