# radiosity.cmake - tests of the radiosity application (apps/radiosity) and of
# `vwalls radiosity`. Each runs in well under 30 s on 2 cores (RelWithDebInfo).

add_executable(test_radiosity ${PROJECT_SOURCE_DIR}/tests/radiosity/test_radiosity.c)
target_include_directories(test_radiosity PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_radiosity PRIVATE vwalls_apps m)

foreach(t ffsum parallel perpendicular box layouts checkpoint)
  add_test(NAME radiosity_${t} COMMAND test_radiosity ${t})
  set_tests_properties(radiosity_${t} PROPERTIES LABELS "radiosity;threads" TIMEOUT 60)
endforeach()
