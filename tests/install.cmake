# install.cmake - tests of vwalls as a library for other people's programs: the shared
# library exports exactly the public API; the version has one source; the API reference
# builds without warnings; and an installed tree (cmake --install into a temporary
# prefix) builds and runs the examples and the tutorial out of tree, with pkg-config and
# with find_package (label "install", about a minute).

add_test(NAME install_symbols
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/symbols.sh $<TARGET_FILE:vwalls>
                 ${PROJECT_SOURCE_DIR}/include/vwalls ${PROJECT_BINARY_DIR}/include/vwalls)
# nosan: a sanitizer build exports its instrumentation too; the contract is the plain build.
set_tests_properties(install_symbols PROPERTIES LABELS "install;nosan")

# No binary of the build tree searches the current directory for its libraries.
add_test(NAME install_runpath
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/runpath.sh $<TARGET_FILE:vwalls_tool>
                 $<TARGET_FILE:vwalls>)
set_tests_properties(install_runpath PROPERTIES LABELS "install")

# vw_version() (from the generated header) is the CMake project version.
add_test(NAME install_version COMMAND vwalls_tool --version)
set_tests_properties(install_version PROPERTIES LABELS "install"
                     PASS_REGULAR_EXPRESSION "^vwalls ${PROJECT_VERSION}\n$")

if(TARGET docs)
  add_test(NAME docs_api
           COMMAND sh -c "\"$0\" --build \"$1\" --target docs >/dev/null && if [ -s \"$2\" ]; then cat \"$2\"; exit 1; fi"
                   ${CMAKE_COMMAND} ${PROJECT_BINARY_DIR} ${PROJECT_BINARY_DIR}/docs/doxygen-warnings.txt)
  set_tests_properties(docs_api PROPERTIES LABELS "install;docs" RESOURCE_LOCK vw_docs)
endif()

# The installed tree must be complete: build everything it contains first (ctest does
# not build), which `./run test` and CI do.
set(_vw_install_mpi "")
if(VW_HAVE_MPI)
  set(_vw_install_mpi ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG})
endif()
add_test(NAME install_out_of_tree
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/run.sh ${PROJECT_BINARY_DIR}
                 ${PROJECT_SOURCE_DIR}/tests/install ${CMAKE_C_COMPILER} ${PROJECT_VERSION}
                 ${CMAKE_INSTALL_DOCDIR} ${CMAKE_INSTALL_LIBDIR} ${_vw_install_mpi})
# nosan: a program built out of tree without the sanitizer flags cannot link an
# instrumented library.
set_tests_properties(install_out_of_tree PROPERTIES LABELS "install;nosan" TIMEOUT 300 PROCESSORS 2
  RESOURCE_LOCK vw_docs
  ENVIRONMENT "${VW_MPI_ENV};OMPI_MCA_rmaps_base_oversubscribe=1")

# The man page documents every subcommand and every option their --help shows.
add_test(NAME install_man_options
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/man_options.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR}/docs/man/vwalls.1)
set_tests_properties(install_man_options PROPERTIES LABELS "install;docs")

# The other way: every vwalls command the docs show (README.md, BENCHMARKS.md, docs/*.md
# and the man page) is one the program takes: its subcommand, its options as --help
# shows them, and its arguments as the command reads them; `./run X` and bench/NAME.sh too.
add_test(NAME docs_commands
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/doc_commands.sh $<TARGET_FILE:vwalls_tool>
                 ${PROJECT_SOURCE_DIR})
set_tests_properties(docs_commands PROPERTIES LABELS "install;docs")

# The C shown in docs/tutorial.md is the C that tests/examples.cmake builds and runs.
file(GLOB _vw_tutorial_sources ${PROJECT_SOURCE_DIR}/docs/tutorial/*.c ${PROJECT_SOURCE_DIR}/docs/tutorial/*.h)
add_test(NAME docs_tutorial_snippets
         COMMAND sh ${PROJECT_SOURCE_DIR}/tests/install/tutorial_snippets.sh
                 ${PROJECT_SOURCE_DIR}/docs/tutorial.md ${_vw_tutorial_sources})
set_tests_properties(docs_tutorial_snippets PROPERTIES LABELS "install;docs")
