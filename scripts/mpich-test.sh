#!/bin/sh
# mpich-test.sh - builds vwalls against MPICH in its own build directory (Open MPI stays
# the system default) and runs the MPI tests there: the engine must not depend on one
# MPI implementation. Installs libmpich-dev and mpich when missing (Debian).
# usage: scripts/mpich-test.sh [BUILD_DIR]   (default: build-mpich next to this script's repo)
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$repo/build-mpich}
# The same idempotent installer as ./run (apt-get update first when anything is missing).
"$repo/scripts/setup.sh" build mpich
# Keep the system default MPI whatever its priority was (installing MPICH may switch
# the Debian alternatives to it); this script only points CMake at MPICH's wrappers.
cmake -S "$repo" -B "$build" -DVW_WERROR=ON \
      -DMPI_C_COMPILER=/usr/bin/mpicc.mpich -DMPIEXEC_EXECUTABLE=/usr/bin/mpiexec.mpich >/dev/null
grep -q 'MPI_C_LIB_NAMES:INTERNAL=.*mpich' "$build/CMakeCache.txt" ||
    grep -qi 'mpich' "$build/CMakeCache.txt" || { echo "mpich-test.sh: CMake did not pick MPICH"; exit 1; }
cmake --build "$build" -j2
cd "$build"
ctest -L mpi --output-on-failure -j2 --timeout 180
