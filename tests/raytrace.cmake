# raytrace.cmake - tests of the distributed ray tracer (apps/raytrace) and the
# Embree-raw benchmark helper. Images are compared bit for bit: docs/raytrace.md promises
# identical images for every decomposition, worker count and engine.

add_executable(vw_test_raytrace ${PROJECT_SOURCE_DIR}/tests/raytrace/rt_test.c)
target_link_libraries(vw_test_raytrace PRIVATE vwalls_apps)

set(VW_RT_MIXED ${PROJECT_SOURCE_DIR}/tests/raytrace/mixed.nff)

add_test(NAME raytrace_cone COMMAND vw_test_raytrace cone)
add_test(NAME raytrace_scale COMMAND vw_test_raytrace scale)
add_test(NAME raytrace_analytic COMMAND vw_test_raytrace analytic)
# The eye rays span the NFF angle, up to the reader's limit of 180 degrees.
add_test(NAME raytrace_view COMMAND vw_test_raytrace view)
add_test(NAME raytrace_hitcells COMMAND vw_test_raytrace hitcells)
# The same scene 1e10 times its size from the origin: Embree sees it measured from the
# world box's centre (rt_float_frame; at 1e5 it was 76/255 off, at 1e8 178/255), and a
# shadow ray starts clear of its own surface by more than the doubles' rounding there
# (eps, rt_float_frame_norm1).
add_test(NAME raytrace_analytic_far COMMAND vw_test_raytrace analytic 1e10)
# A small ball on a wide floor casts its shadow: a secondary ray's least t is set by the
# float error, not by the scene's size (1e-4 of the diagonal skipped the ball).
add_test(NAME raytrace_contact COMMAND vw_test_raytrace contact)
# A light exactly on a surface (a floor, a ball) lights what faces it: the shadow ray
# stops short of the light instead of finding the surface the light lies on.
add_test(NAME raytrace_lighton COMMAND vw_test_raytrace lighton)
# Rays aimed at the edges and vertices a mesh's triangles share do not slip through.
add_test(NAME raytrace_watertight COMMAND vw_test_raytrace watertight)
# MTL illum: Ks weights the mirror ray from illum 3 on (and without an illum), not for
# illum 2, which exporters write for a plain material with a highlight.
add_test(NAME raytrace_illum COMMAND vw_test_raytrace illum
         ${PROJECT_SOURCE_DIR}/tests/data/good/illum.obj)
# Concave polygons (the SPD gears' faces) become triangles inside them, not a fan.
add_test(NAME raytrace_concave COMMAND vw_test_raytrace concave
         ${PROJECT_SOURCE_DIR}/tests/data/good/concave.nff)
# The scene's records a part at a time equal the whole conversion (rt_job_create adds
# them so): every entity kind, concave polygons, the sphereflake.
add_test(NAME raytrace_parts_mixed COMMAND vw_test_raytrace parts
         ${PROJECT_SOURCE_DIR}/tests/data/good/mixed.nff)
add_test(NAME raytrace_parts_concave COMMAND vw_test_raytrace parts
         ${PROJECT_SOURCE_DIR}/tests/data/good/concave.nff)
add_test(NAME raytrace_parts_balls COMMAND vw_test_raytrace parts gen:balls:2)
# Layouts 1, 2, 2x4, 2x2x2, 4x4x4 x workers 1, 2, 4 against 1 cell on 1 worker; also
# checks that every ray created is ended and that every layout creates the same rays.
add_test(NAME raytrace_identical_balls COMMAND vw_test_raytrace identical gen:balls:2 96x96)
add_test(NAME raytrace_identical_mixed COMMAND vw_test_raytrace identical ${VW_RT_MIXED} 96x96)
# Hits on a wall: the overlap of a cell's search past its far wall (walk_ray).
add_test(NAME raytrace_identical_wall_hit COMMAND vw_test_raytrace identical
         ${PROJECT_SOURCE_DIR}/tests/raytrace/wall_hit.nff 8x6)
# The eye on two walls, and eye, shadow, mirror and refracted rays lying in them.
add_test(NAME raytrace_identical_wall_eye COMMAND vw_test_raytrace identical
         ${PROJECT_SOURCE_DIR}/tests/raytrace/wall_eye.nff 33x33)
# The same under the stress switch (random delays and reordering of deliveries).
add_test(NAME raytrace_stress_balls COMMAND vw_test_raytrace identical gen:balls:2 64x64)
add_test(NAME raytrace_stress_mixed COMMAND vw_test_raytrace identical ${VW_RT_MIXED} 64x64)
# A PLY mesh (binary, coloured faces): the same image on every layout and worker count.
add_test(NAME raytrace_identical_ply COMMAND vw_test_raytrace identical
         ${PROJECT_SOURCE_DIR}/tests/data/good/pyramid.ply 48x48)
# The two scenes above a billion units from the origin (raytrace_cli: the same PNG too).
add_test(NAME raytrace_identical_far_mixed COMMAND vw_test_raytrace identical
         ${PROJECT_SOURCE_DIR}/tests/raytrace/far_mixed.nff 96x96)
add_test(NAME raytrace_identical_far_wall_hit COMMAND vw_test_raytrace identical
         ${PROJECT_SOURCE_DIR}/tests/raytrace/far_wall_hit.nff 8x6)
set(VW_RT_TSAN "TSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/raytrace/tsan.supp")
set_tests_properties(raytrace_cone raytrace_analytic raytrace_analytic_far raytrace_identical_balls
  raytrace_identical_mixed raytrace_identical_wall_hit raytrace_identical_far_mixed
  raytrace_identical_far_wall_hit raytrace_identical_ply PROPERTIES ENVIRONMENT "${VW_RT_TSAN}")
# Threads-engine tests: ./run test-sanitizers runs them under TSan (rays handed from
# cell to cell inline and by message, under the stress switch too).
set_tests_properties(raytrace_cone raytrace_analytic raytrace_analytic_far raytrace_identical_balls
  raytrace_identical_mixed raytrace_identical_wall_hit raytrace_stress_balls raytrace_stress_mixed
  raytrace_identical_far_mixed raytrace_identical_far_wall_hit raytrace_identical_ply
  PROPERTIES LABELS "threads")
set_tests_properties(raytrace_stress_balls PROPERTIES ENVIRONMENT "VW_STRESS=7;${VW_RT_TSAN}")
set_tests_properties(raytrace_stress_mixed PROPERTIES
  ENVIRONMENT "VW_STRESS=1994;VW_STRESS_SPLIT=1;${VW_RT_TSAN}")

# The command line: PNG files byte-identical across layouts and workers, the stats JSON,
# exit status 2 and no output file for a bad scene.
add_test(NAME raytrace_cli
  COMMAND ${CMAKE_COMMAND} -DVWALLS=$<TARGET_FILE:vwalls_tool> -DSCENE=${VW_RT_MIXED}
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/raytrace_cli
          -P ${PROJECT_SOURCE_DIR}/tests/raytrace/cli.cmake)
set_tests_properties(raytrace_cli PROPERTIES ENVIRONMENT "${VW_RT_TSAN}")

# No message to a cell of the sender's own worker: crossings and new rays go inline.
add_test(NAME raytrace_inline_spawn
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/inline_spawn.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/raytrace_inline_spawn)
set_tests_properties(raytrace_inline_spawn PROPERTIES LABELS "threads" TIMEOUT 60
                     ENVIRONMENT "${VW_RT_TSAN}")

# --world: the walls divide the box given, not only the objects' bounds (the paper's
# clustered load cases); the same image; a bad box refused.
add_test(NAME raytrace_world_box
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/world_box.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/raytrace_world_box)
set_tests_properties(raytrace_world_box PROPERTIES LABELS "threads" TIMEOUT 60
                     ENVIRONMENT "${VW_RT_TSAN}")

# vwalls bench: a row per configuration in order, the images checked identical (a
# difference fails it), bad options refused with nothing written (tests/raytrace/cli_bench.sh).
add_test(NAME raytrace_cli_bench
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/cli_bench.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/raytrace_cli_bench)
set_tests_properties(raytrace_cli_bench PROPERTIES ENVIRONMENT "${VW_RT_TSAN}" TIMEOUT 120)

# bench/raytrace.sh: Embree's raw ray-casting rate for the same rays (the kernel limit).
if(EXISTS ${PROJECT_SOURCE_DIR}/bench/embree_raw.c)
  add_executable(vw_bench_embree_raw ${PROJECT_SOURCE_DIR}/bench/embree_raw.c)
  target_link_libraries(vw_bench_embree_raw PRIVATE vwalls_apps)
  # Its time and rate agree to the digits the benchmarks divide.
  add_test(NAME bench_embree_raw
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/embree_raw.sh
                   $<TARGET_FILE:vw_bench_embree_raw> ${PROJECT_SOURCE_DIR}/tests/raytrace/mixed.nff)
  set_tests_properties(bench_embree_raw PROPERTIES LABELS "bench")
endif()

# bench/nff2pov.py (POV-Ray, the benchmark's reference) converts concave polygons so
# that povray covers the pixels vwalls covers. Skipped without povray or python3.
add_test(NAME bench_nff2pov_concave
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/nff2pov.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR}/bench/nff2pov.py ${PROJECT_SOURCE_DIR}/tests/data/good/concave.nff
                 ${CMAKE_CURRENT_BINARY_DIR}/bench_nff2pov_concave covered)
set_tests_properties(bench_nff2pov_concave PROPERTIES LABELS "bench" SKIP_RETURN_CODE 77 TIMEOUT 60)
# ... and the '#vw Ks' and '#vw Ke' extension lines so that povray draws vwalls' image
# (within 0.02 a channel), and says on stderr what POV-Ray cannot draw.
add_test(NAME bench_nff2pov_ext
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/nff2pov.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR}/bench/nff2pov.py ${PROJECT_SOURCE_DIR}/tests/raytrace/nff2pov_ext.nff
                 ${CMAKE_CURRENT_BINARY_DIR}/bench_nff2pov_ext within)
set_tests_properties(bench_nff2pov_ext PROPERTIES LABELS "bench" SKIP_RETURN_CODE 77 TIMEOUT 60)

# Under mpirun (when the build has MPI; launcher flags: cmake/mpi_launcher.cmake): the
# same PNG bytes as the threads engine.
if(VW_HAVE_MPI AND MPIEXEC_EXECUTABLE)
  string(REPLACE ";" "|" _vw_rt_pre "${VW_MPI_PREFLAGS}")
  add_test(NAME raytrace_mpi
    COMMAND ${CMAKE_COMMAND} -DVWALLS=$<TARGET_FILE:vwalls_tool> -DSCENE=${VW_RT_MIXED}
            -DWORK=${CMAKE_CURRENT_BINARY_DIR}/raytrace_mpi -DMPIRUN=${MPIEXEC_EXECUTABLE}
            -DNPFLAG=${MPIEXEC_NUMPROC_FLAG} "-DPREFLAGS=${_vw_rt_pre}"
            -P ${PROJECT_SOURCE_DIR}/tests/raytrace/mpi.cmake)
  set_tests_properties(raytrace_mpi PROPERTIES LABELS "mpi" TIMEOUT 120 PROCESSORS 2
    ENVIRONMENT "${VW_MPI_ENV};${VW_RT_TSAN}")
  # vwalls bench under mpirun: the same checks, the table from the first process only.
  add_test(NAME raytrace_cli_bench_mpi
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/raytrace/cli_bench.sh $<TARGET_FILE:vwalls_tool>
                   ${CMAKE_CURRENT_BINARY_DIR}/raytrace_cli_bench_mpi
                   "${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${VW_MPI_PREFLAGS}")
  set_tests_properties(raytrace_cli_bench_mpi PROPERTIES LABELS "mpi" TIMEOUT 240 PROCESSORS 2
    ENVIRONMENT "${VW_MPI_ENV}")
endif()
