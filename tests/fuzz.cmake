# fuzz.cmake - every fuzz target (tests/fuzz/fuzz_*.c) also built with a plain main that
# replays files (tests/fuzz/replay.c), so its checks run in every build, sanitizers
# included, without clang or libFuzzer: on the good, bad and warned-about scenes and edit scripts of
# tests/data, the ray tracer's test scenes and the fuzzers' findings (tests/fuzz/findings: scenes that
# made fuzz_render abort, kept as they were found). `./run fuzz` is the fuzzing itself.
file(GLOB VW_FUZZ_TARGETS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/fuzz/fuzz_*.c)
file(GLOB VW_FUZZ_INPUTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/data/good/*
     ${PROJECT_SOURCE_DIR}/tests/data/bad/* ${PROJECT_SOURCE_DIR}/tests/data/warn/*
     ${PROJECT_SOURCE_DIR}/tests/data/edits/*
     ${PROJECT_SOURCE_DIR}/tests/raytrace/*.nff
     ${PROJECT_SOURCE_DIR}/tests/fuzz/findings/*)
foreach(src ${VW_FUZZ_TARGETS})
  get_filename_component(name ${src} NAME_WE)
  add_executable(replay_${name} ${src} ${PROJECT_SOURCE_DIR}/tests/fuzz/replay.c)
  target_link_libraries(replay_${name} PRIVATE vwalls_static vwalls_apps)
  add_test(NAME fuzz_replay_${name} COMMAND replay_${name} ${VW_FUZZ_INPUTS})
  set_tests_properties(fuzz_replay_${name} PROPERTIES LABELS "threads")
endforeach()
