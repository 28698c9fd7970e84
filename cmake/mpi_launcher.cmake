# mpi_launcher.cmake - how the tests start MPI jobs, worked out once for every
# tests/*.cmake (included before them):
#   VW_MPI_PREFLAGS  MPIEXEC_PREFLAGS, plus --oversubscribe for Open MPI (to start more
#                    processes than cores; MPICH does not know the flag)
#   VW_MPI_FLAVOUR   openmpi or mpich
#   VW_MPI_ENV       the environment that lets Open MPI run as root (CI runs as root)
set(VW_MPI_PREFLAGS "")
set(VW_MPI_FLAVOUR "")
set(VW_MPI_ENV "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
if(VW_HAVE_MPI AND MPIEXEC_EXECUTABLE)
  set(VW_MPI_PREFLAGS ${MPIEXEC_PREFLAGS})
  set(VW_MPI_FLAVOUR mpich)
  execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE _vw_mpiexec_version
                  ERROR_QUIET)
  if(_vw_mpiexec_version MATCHES "Open MPI|OpenRTE")
    set(VW_MPI_FLAVOUR openmpi)
    list(APPEND VW_MPI_PREFLAGS --oversubscribe)
  endif()
endif()
