# install.cmake - what `cmake --install` puts where: the shared and static library, the
# public headers (with the generated version.h), the vwalls command, its man page, a
# CMake package (find_package(vwalls) -> vwalls::vwalls) and a pkg-config file, and the
# example modules and tutorial sources as documentation. Included by CMakeLists.txt.

include(CMakePackageConfigHelpers)

set(VW_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/vwalls)

install(TARGETS vwalls vwalls_static
  EXPORT vwallsTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The command is statically linked with the library, so it needs no rpath to it; it is
# not part of the export set (nobody links against it).
install(TARGETS vwalls_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The installed binaries are built with their installed RUNPATH (the directories of the
# libraries they link outside the build tree: MPI's), so the install copies them as they
# are. Otherwise CMake pads the build tree's RUNPATH with ':' for the install to rewrite
# it in place, and that empty entry makes the loader search the current directory for
# libpng, zlib, MPI and Embree: any library of those names there would be loaded.
# (tests/install/runpath.sh checks.)
set_target_properties(vwalls vwalls_tool PROPERTIES BUILD_WITH_INSTALL_RPATH ON
                      INSTALL_RPATH_USE_LINK_PATH ON)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/vwalls DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/vwalls/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vwalls)

# CMake package: relocatable (paths relative to the installed config file).
install(EXPORT vwallsTargets NAMESPACE vwalls:: DESTINATION ${VW_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vwallsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/vwallsConfig.cmake INSTALL_DESTINATION ${VW_CMAKE_DIR})
# Before 1.0 a minor release may break the API, so only the same major.minor matches.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/vwallsConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/vwallsConfig.cmake
              ${PROJECT_BINARY_DIR}/cmake/vwallsConfigVersion.cmake
        DESTINATION ${VW_CMAKE_DIR})

# pkg-config: prefix relative to ${pcfiledir}, so `cmake --install --prefix X` (which
# cannot re-run configure_file) still gives a file that points into X.
set(_vw_pcdir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${_vw_pcdir}")
  set(VW_PC_RELATIVE_PREFIX "")
  set(VW_PC_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
else()
  file(RELATIVE_PATH VW_PC_RELATIVE_PREFIX /vw_prefix/${_vw_pcdir} /vw_prefix)
  string(REGEX REPLACE "/$" "" VW_PC_RELATIVE_PREFIX "${VW_PC_RELATIVE_PREFIX}")
  set(VW_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(VW_PC_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
else()
  set(VW_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
# MPI as CMake found it (the same MPI the library was built with), as public flags: the
# CMake package makes MPI::MPI_C public too.
set(VW_PC_MPI_CFLAGS "")
set(VW_PC_MPI_LIBS "")
if(VW_HAVE_MPI)
  foreach(dir ${MPI_C_INCLUDE_DIRS})
    string(APPEND VW_PC_MPI_CFLAGS " -I${dir}")
  endforeach()
  foreach(opt ${MPI_C_COMPILE_OPTIONS})
    string(APPEND VW_PC_MPI_CFLAGS " ${opt}")
  endforeach()
  foreach(def ${MPI_C_COMPILE_DEFINITIONS})
    string(APPEND VW_PC_MPI_CFLAGS " -D${def}")
  endforeach()
  foreach(lib ${MPI_C_LIBRARIES})
    if(lib MATCHES "^(.*)/lib([^/]+)\\.so$")
      string(APPEND VW_PC_MPI_LIBS " -L${CMAKE_MATCH_1} -l${CMAKE_MATCH_2}")
    elseif(IS_ABSOLUTE "${lib}")
      string(APPEND VW_PC_MPI_LIBS " ${lib}")
    else()
      string(APPEND VW_PC_MPI_LIBS " -l${lib}")
    endif()
  endforeach()
  foreach(flag ${MPI_C_LINK_FLAGS})
    string(APPEND VW_PC_MPI_LIBS " ${flag}")
  endforeach()
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/vwalls.pc.in ${PROJECT_BINARY_DIR}/vwalls.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/vwalls.pc DESTINATION ${_vw_pcdir})

install(FILES ${PROJECT_SOURCE_DIR}/docs/man/vwalls.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

# The examples and the tutorial, to read and to build against the installed library.
install(FILES ${PROJECT_SOURCE_DIR}/examples/pairs.c ${PROJECT_SOURCE_DIR}/examples/pairs.h
              ${PROJECT_SOURCE_DIR}/examples/sphere_bins.h
              ${PROJECT_SOURCE_DIR}/examples/components.c ${PROJECT_SOURCE_DIR}/examples/components.h
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/tutorial DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/docs/tutorial.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
