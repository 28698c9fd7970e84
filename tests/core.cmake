# core.cmake - tests of the decomposition, the runtime and the example module.
# Label "threads": tests of the threads engine, also run under ThreadSanitizer by CI.

function(vw_core_test name)
  add_executable(${name} ${PROJECT_SOURCE_DIR}/tests/core/${name}.c)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_link_libraries(${name} PRIVATE vwalls_static m)
  target_compile_definitions(${name} PRIVATE _GNU_SOURCE)
endfunction()

vw_core_test(test_decomp)
# What the host gives the process (host.c): hosts laid out in a directory.
vw_core_test(test_host)
target_include_directories(test_host PRIVATE ${PROJECT_SOURCE_DIR}/src)
add_test(NAME core_host COMMAND test_host)
add_test(NAME core_decomp COMMAND test_decomp)
set_tests_properties(core_decomp PROPERTIES LABELS "core")
# Face neighbour lists against brute force, on random kd-trees (staggered, divided, grids;
# 1 to 3 dimensions) and their clones: the same cells, in the same order.
vw_core_test(test_neighbours)
add_test(NAME core_neighbours COMMAND test_neighbours)
set_tests_properties(core_neighbours PROPERTIES LABELS "core")

# The message storm (test_storm.c), on the threads engine here; the same program is the
# MPI engine's storm and its agreement, fault and failure tests (mpi.cmake), so it knows
# whether the build has MPI.
vw_core_test(test_storm)
target_compile_definitions(test_storm PRIVATE VW_HAVE_MPI=${VW_HAVE_MPI})
add_test(NAME core_storm COMMAND test_storm 20)
add_test(NAME core_storm_stress COMMAND test_storm 8 --stress)
add_test(NAME core_storm_split COMMAND test_storm 4 --stress)
set_tests_properties(core_storm_split PROPERTIES ENVIRONMENT "VW_STRESS_SPLIT=1")
set_tests_properties(core_storm core_storm_stress core_storm_split PROPERTIES LABELS "core;threads")

# A module's mistakes get a message: a failed create says why (vw_world_errmsg(NULL)),
# a post of a kind without handle is refused, a bad send or count stops the process
# naming it.
vw_core_test(test_misuse)
add_test(NAME core_misuse_create COMMAND test_misuse create)
add_test(NAME core_misuse_post COMMAND test_misuse post)
# Calls a careless or hostile program makes: a bad mapping for new walls leaves the world
# as it was, counts too large for memory are refused, phases keep their names, the
# slow-down factors are the world's own copy, signals need no buffer.
add_test(NAME core_misuse_redecompose COMMAND test_misuse redecompose)
add_test(NAME core_misuse_limits COMMAND test_misuse limits)
add_test(NAME core_misuse_stats COMMAND test_misuse stats)
add_test(NAME core_misuse_slowdown COMMAND test_misuse slowdown)
add_test(NAME core_misuse_signal COMMAND test_misuse signal)
# Failed calls say why (map.h's too), queries take a NULL world, bad workers are
# refused (by vw_engine_workers too), vw_world_done asks every cell.
foreach(m errmsg null workers done maperr)
  add_test(NAME core_misuse_${m} COMMAND test_misuse ${m})
endforeach()
set_tests_properties(core_misuse_create core_misuse_post core_misuse_redecompose
  core_misuse_limits core_misuse_stats core_misuse_slowdown core_misuse_signal
  core_misuse_errmsg core_misuse_null core_misuse_workers core_misuse_done
  core_misuse_maperr PROPERTIES LABELS "core")
# An overflowed size loops; a slow-down read from the caller's array spins: both hang.
set_tests_properties(core_misuse_limits core_misuse_slowdown PROPERTIES TIMEOUT 30)
foreach(case "send;sent message kind 1 ('to_output') to cell 0, but the kind has no handle (an output kind: sent with vw_send_output)"
             "output;sent message kind 0 ('to_cell') to the output, but the kind has no output handler"
             "count;counted into counter 5 of 1"
             "count-all;counted into counter 5 of 1"
             "face;sent message kind 0 to face 6 (faces are 0..5)"
             "build-send;sent message kind 0 from cell 0 outside a run"
             "send-null;sent message kind 0 of 4 bytes with no message (NULL)"
             "point-null;sent message kind 0 of 4 bytes with no message (NULL)"
             "reenter-run;called vw_world_run from a callback during a run"
             "reenter-post;called vw_world_post from a callback during a run"
             "reenter-add;called vw_world_add_objects from a callback during a run"
             "reenter-free;called vw_world_free from a callback during a run"
             "reenter-commit;called vw_world_commit from a callback during the cells"
             "reenter-agree;called vw_world_agree from a callback during a run"
             "build-agree;called vw_world_agree from a callback during the cells"
             "reenter-traffic;called vw_world_traffic from a callback during a run"
             "bad-kind;sent unknown message kind 7 (it has 2 kinds)"
             "bad-cell;sent to cell 99, which does not exist (2 cells)"
             "norestore-step;returned from step() of cell 0 in cell 1"
             "norestore-handle;returned from its handler of a kind 0 message to cell 0 in another cell"
             "enter-output;entered cell 1 with message kind 1 ('to_output'), but the kind has no handle (an output kind: sent with vw_send_output)"
             "build-enter;entered cell 0 with message kind 1 ('to_output'), but the kind has no handle")
  list(GET case 0 m)
  list(GET case 1 want)
  add_test(NAME core_misuse_${m} COMMAND test_misuse ${m} ${want})
  # A call back into the world used to wait for its own run for ever.
  set_tests_properties(core_misuse_${m} PROPERTIES LABELS "core" TIMEOUT 30)
endforeach()

# The sized sends (VW_SEND_CELL, ...): records of the kind's size arrive whole through
# every one; a record of another size (shorter: every message was cut; longer: the send
# read past it) stops the process naming the call, the kind and both sizes.
vw_core_test(test_sized)
add_test(NAME core_sized_ok COMMAND test_sized ok)
set_tests_properties(core_sized_ok PROPERTIES LABELS "core;threads" TIMEOUT 30)
foreach(case "cell-small;gave vw_send_cell_sized a record of 24 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "cell-large;gave vw_send_cell_sized a record of 40 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "pointer;gave vw_send_cell_sized a record of 8 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "point;gave vw_send_point_sized a record of 24 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "point-outside;gave vw_send_point_sized a record of 40 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "face;gave vw_send_face_sized a record of 24 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "face-wall;gave vw_send_face_sized a record of 24 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "neighbours;gave vw_send_neighbours_sized a record of 40 bytes for message kind 0 ('rec'), whose size is 32 bytes"
             "output;gave vw_send_output_sized a record of 24 bytes for message kind 1 ('out'), whose size is 32 bytes"
             "signal;gave vw_send_cell_sized a record of 24 bytes for message kind 2 ('signal'), whose size is 0 bytes")
  list(GET case 0 m)
  list(GET case 1 want)
  add_test(NAME core_sized_${m} COMMAND test_sized ${m} ${want})
  set_tests_properties(core_sized_${m} PROPERTIES LABELS "core" TIMEOUT 30)
endforeach()

# The example module equals the O(n^2) count for every layout and worker count.
foreach(layout 1 2x4 2x2x2 4x4x4)
  foreach(workers 1 2 4)
    add_test(NAME example_pairs_${layout}_w${workers}
             COMMAND vwalls_tool example-pairs --spheres 3000 --radius 0.03 --seed 5
                     --cells ${layout} --workers ${workers} --check --quiet)
    set_tests_properties(example_pairs_${layout}_w${workers} PROPERTIES LABELS "core;threads")
  endforeach()
endforeach()
add_test(NAME example_pairs_stress
         COMMAND vwalls_tool example-pairs --spheres 3000 --radius 0.03 --cells 4x4x4 --workers 4 --check)
set_tests_properties(example_pairs_stress PROPERTIES LABELS "core;threads" ENVIRONMENT "VW_STRESS=99")

# Bad usage: exit status 2 and a one-line message naming what is wrong.
foreach(bad "--cells;2x" "--cells;0" "--cells;99x99x99" "--workers;0" "--spheres;-3" "--bogus")
  string(REPLACE ";" "_" tname "${bad}")
  string(REGEX REPLACE "[^A-Za-z0-9_]" "" tname "${tname}")
  add_test(NAME cli_bad_${tname} COMMAND vwalls_tool example-pairs ${bad})
  set_tests_properties(cli_bad_${tname} PROPERTIES LABELS "core" WILL_FAIL TRUE)
endforeach()
add_test(NAME cli_unknown_command COMMAND vwalls_tool frobnicate)
set_tests_properties(cli_unknown_command PROPERTIES LABELS "core" WILL_FAIL TRUE)

# Farmed work: every batch of a duplicated cell made once, turns taken when asked.
vw_core_test(test_farm)
add_test(NAME core_farm COMMAND test_farm)
add_test(NAME core_farm_stress COMMAND test_farm --stress)
set_tests_properties(core_farm core_farm_stress PROPERTIES LABELS "core;threads")

# Corner cases of the worker loop: a step() that sends and reports no work, the meter
# after its list of noted units filled up, runs after one whose threads did not start,
# hand-offs tried outside a run, a cell_build that fails (its state is not the runtime's),
# a run that fails part-way (vw_ctx_fail, a packet that cannot be allocated).
vw_core_test(test_runtime)
target_link_options(test_runtime PRIVATE -Wl,--wrap=pthread_create -Wl,--wrap=malloc)
foreach(t step-send meter thread-fail build-enter build-fail run-fail)
  add_test(NAME core_runtime_${t} COMMAND test_runtime ${t})
  set_tests_properties(core_runtime_${t} PROPERTIES LABELS "core;threads" TIMEOUT 60)
endforeach()
add_test(NAME core_runtime_step-send_stress COMMAND test_runtime step-send)
add_test(NAME core_runtime_run-fail_stress COMMAND test_runtime run-fail)
set_tests_properties(core_runtime_step-send_stress core_runtime_run-fail_stress PROPERTIES
                     LABELS "core;threads" TIMEOUT 60 ENVIRONMENT "VW_STRESS=5")
