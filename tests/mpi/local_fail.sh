#!/bin/sh
# local_fail.sh - one step of a world's life (create, add, update, replicas, redecompose,
# commit, run) fails on rank 1 of NP only (test_storm --fail). Every rank must fail
# that same step with rank 1's message ("rank 1: ...") and exit non-zero, within 20 s:
# a rank that went on alone would wait for the others in the next collective call, and
# they for it in MPI_Finalize, for ever.
# usage: local_fail.sh STEP NP TEST_STORM "MPIEXEC -n NP [flags]"
step=$1 np=$2 prog=$3 launch=$4
. "$(dirname "$0")/must_fail.sh"
# shellcheck disable=SC2086
base_ms=$(startup_ms $launch "$prog" --seeds 0)
# shellcheck disable=SC2086
must_fail "local_fail.sh: $step" 20 30 $launch "$prog" --workers 2 --fail "$step" --fail-rank 1
r=0
while [ "$r" -lt "$np" ]; do
    line=$(grep "^test_storm: process $r: " "$out")
    if [ -z "$line" ]; then
        echo "local_fail.sh: FAIL: process $r said nothing (it did not fail the step)"
        fail=1
    elif ! printf '%s\n' "$line" | grep -q "^test_storm: process $r: $step failed ([^)]*): rank 1: "; then
        echo "local_fail.sh: FAIL: process $r did not fail $step with rank 1's message"
        fail=1
    fi
    r=$((r + 1))
done
grep -q "UNEXPECTED" "$out" && { echo "local_fail.sh: FAIL: a process reported the unexpected"; fail=1; }
rm -f "$out"
exit $fail
