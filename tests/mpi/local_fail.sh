#!/bin/sh
# local_fail.sh - one step of a world's life (create, add, update, replicas, redecompose,
# commit, run) fails on rank 1 of NP only (test_mpi_storm --fail). Every rank must fail
# that same step with rank 1's message ("rank 1: ...") and exit non-zero, within 20 s:
# a rank that went on alone would wait for the others in the next collective call, and
# they for it in MPI_Finalize, for ever.
# usage: local_fail.sh STEP NP TEST_MPI_STORM "MPIEXEC -n NP [flags]"
step=$1 np=$2 prog=$3 launch=$4
out=$(mktemp)
start=$(date +%s%N)
# shellcheck disable=SC2086
timeout 30 $launch "$prog" --workers 2 --fail "$step" --fail-rank 1 >"$out" 2>&1
rc=$?
end=$(date +%s%N)
ms=$(( (end - start) / 1000000 ))
cat "$out"
echo "local_fail.sh: $step: status $rc after $ms ms"
fail=0
[ "$rc" -ne 0 ] || { echo "local_fail.sh: FAIL: the job succeeded although rank 1 failed"; fail=1; }
[ "$rc" -ne 124 ] || { echo "local_fail.sh: FAIL: the job hung (killed by timeout)"; fail=1; }
[ "$ms" -le 20000 ] || { echo "local_fail.sh: FAIL: took $ms ms, more than 20 s"; fail=1; }
r=0
while [ "$r" -lt "$np" ]; do
    line=$(grep "^test_mpi_storm: process $r: " "$out")
    if [ -z "$line" ]; then
        echo "local_fail.sh: FAIL: process $r said nothing (it did not fail the step)"
        fail=1
    elif ! printf '%s\n' "$line" | grep -q "^test_mpi_storm: process $r: $step failed ([^)]*): rank 1: "; then
        echo "local_fail.sh: FAIL: process $r did not fail $step with rank 1's message"
        fail=1
    fi
    r=$((r + 1))
done
grep -q "UNEXPECTED" "$out" && { echo "local_fail.sh: FAIL: a process reported the unexpected"; fail=1; }
rm -f "$out"
exit $fail
