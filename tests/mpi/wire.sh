#!/bin/sh
# wire.sh - rank 1 sends rank 0 a message of a kind rank 0's module does not have
# (test_mpi_storm --wire). Rank 0 must stop the job within 20 s, non-zero, saying which
# rank sent the malformed packet and what is wrong with it.
# usage: wire.sh TEST_MPI_STORM "MPIEXEC -n 2 [flags]"
prog=$1 launch=$2
out=$(mktemp)
start=$(date +%s%N)
# shellcheck disable=SC2086
timeout 30 $launch "$prog" --wire >"$out" 2>&1
rc=$?
end=$(date +%s%N)
ms=$(( (end - start) / 1000000 ))
cat "$out"
echo "wire.sh: status $rc after $ms ms"
fail=0
[ "$rc" -ne 0 ] || { echo "wire.sh: FAIL: the job succeeded"; fail=1; }
[ "$rc" -ne 124 ] || { echo "wire.sh: FAIL: the job hung (killed by timeout)"; fail=1; }
[ "$ms" -le 20000 ] || { echo "wire.sh: FAIL: took $ms ms, more than 20 s"; fail=1; }
grep -q "rank 0: packet from rank 1 .*malformed: message 0 is of kind 2" "$out" ||
    { echo "wire.sh: FAIL: rank 0 did not name the malformed packet and its sender"; fail=1; }
rm -f "$out"
exit $fail
