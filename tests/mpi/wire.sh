#!/bin/sh
# wire.sh - rank 1 sends rank 0 a message of a kind rank 0's module does not have
# (test_mpi_storm --wire). Rank 0 must stop the job within 20 s, non-zero, saying which
# rank sent the malformed packet and what is wrong with it.
# usage: wire.sh TEST_MPI_STORM "MPIEXEC -n 2 [flags]"
prog=$1 launch=$2
. "$(dirname "$0")/must_fail.sh"
# shellcheck disable=SC2086
must_fail wire.sh 20 30 $launch "$prog" --wire
grep -q "rank 0: packet from rank 1 .*malformed: message 0 is of kind 2" "$out" ||
    { echo "wire.sh: FAIL: rank 0 did not name the malformed packet and its sender"; fail=1; }
rm -f "$out"
exit $fail
