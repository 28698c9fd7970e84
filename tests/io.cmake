# tests/io.cmake - tests of src/io: NFF, OBJ and PLY readers, the NFF writer, images, output
# files, the scene generators and the gen/info subcommands. Every test is named io_*.

foreach(t bad nff obj ply image gen)
  add_executable(test_io_${t} ${PROJECT_SOURCE_DIR}/tests/io/test_io_${t}.c)
  target_include_directories(test_io_${t} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_link_libraries(test_io_${t} PRIVATE vwalls_static m)
  add_test(NAME io_${t} COMMAND test_io_${t} ${PROJECT_SOURCE_DIR}/tests/data)
endforeach()
# A reader that loops over a count the file cannot bound (io_ply's empty elements)
# fails by this limit; the test takes a few milliseconds.
set_tests_properties(io_ply PROPERTIES TIMEOUT 60)

# vw_outfile: links followed, devices and FIFOs written in place, modes by the umask,
# no temporary file left by a failure or by SIGTERM (forked writers, 40 rounds, ~1 s).
add_executable(test_io_outfile ${PROJECT_SOURCE_DIR}/tests/io/test_io_outfile.c)
target_include_directories(test_io_outfile PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_io_outfile PRIVATE vwalls_static)
target_compile_definitions(test_io_outfile PRIVATE _GNU_SOURCE)
add_test(NAME io_outfile COMMAND test_io_outfile)
set_tests_properties(io_outfile PROPERTIES TIMEOUT 60)

# The subcommands are tested in-process: their sources are compiled with a test main,
# so this does not depend on tools/vwalls.c registering them. vwalls_apps for info
# --materials, which flags reflectances by the radiosity solver's own checks.
add_executable(test_io_cli ${PROJECT_SOURCE_DIR}/tests/io/test_io_cli.c
  ${PROJECT_SOURCE_DIR}/tools/cmd_gen.c ${PROJECT_SOURCE_DIR}/tools/cmd_info.c
  ${PROJECT_SOURCE_DIR}/tools/cli.c)
target_include_directories(test_io_cli PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/tools)
target_link_libraries(test_io_cli PRIVATE vwalls_apps m)
# cli.c uses clock_gettime, which -std=c11 hides without a feature macro.
target_compile_definitions(test_io_cli PRIVATE _GNU_SOURCE)
add_test(NAME io_cli COMMAND test_io_cli ${PROJECT_SOURCE_DIR}/tests/data)

# The readers' number parser reads every token as strtod does (its fast path included).
add_executable(test_io_number ${PROJECT_SOURCE_DIR}/tests/io/test_io_number.c)
target_include_directories(test_io_number PRIVATE ${PROJECT_SOURCE_DIR}/tests ${PROJECT_SOURCE_DIR}/src)
target_link_libraries(test_io_number PRIVATE vwalls_static m)
add_test(NAME io_number COMMAND test_io_number)

# vw_polygon_triangulate on 90,000 random concave polygons with repeated corners and
# corners passed twice, near and far from the origin: triangles inside, adding up.
add_executable(test_io_triangulate ${PROJECT_SOURCE_DIR}/tests/io/test_io_triangulate.c)
target_include_directories(test_io_triangulate PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_io_triangulate PRIVATE vwalls_static m)
add_test(NAME io_triangulate COMMAND test_io_triangulate)

# The command's output files and its help texts, info --materials, and --stats in every
# command's help with gen's and info's stats JSON (each script says what it checks; a few
# seconds).
foreach(t outputs help args info stats)
  add_test(NAME io_cli_${t}
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/io/cli_${t}.sh $<TARGET_FILE:vwalls_tool>
                   ${CMAKE_CURRENT_BINARY_DIR}/io_cli_${t})
  set_tests_properties(io_cli_${t} PROPERTIES TIMEOUT 60)
endforeach()

# The command-line robustness sweep's cases (tests/io/cli_sweep.sh says what it checks).
add_test(NAME io_cli_sweep
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/io/cli_sweep.sh $<TARGET_FILE:vwalls_tool>
                 ${CMAKE_CURRENT_BINARY_DIR}/io_cli_sweep)
set_tests_properties(io_cli_sweep PROPERTIES TIMEOUT 120)

# What a scene reader takes as text (KIND nff or obj): its C test test_io_KIND_input
# and the command line's tests/io/cli_KIND_input.sh.
function(vw_io_input_tests kind)
  add_executable(test_io_${kind}_input ${PROJECT_SOURCE_DIR}/tests/io/test_io_${kind}_input.c)
  target_include_directories(test_io_${kind}_input PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_link_libraries(test_io_${kind}_input PRIVATE vwalls_static m)
  add_test(NAME io_${kind}_input COMMAND test_io_${kind}_input)
  add_test(NAME io_cli_${kind}_input
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/io/cli_${kind}_input.sh $<TARGET_FILE:vwalls_tool>
                   ${CMAKE_CURRENT_BINARY_DIR}/io_cli_${kind}_input)
  set_tests_properties(io_cli_${kind}_input PROPERTIES TIMEOUT 60)
endfunction()
# OBJ and MTL: binary bytes refused at their line, UTF-8, Latin-1 and a byte order mark
# accepted; one warning per file for unknown keywords.
vw_io_input_tests(obj)
# NFF, as OBJ: a NUL or control byte anywhere (comments included) refused at its line,
# blanks and bytes from 0x80 up accepted.
vw_io_input_tests(nff)
