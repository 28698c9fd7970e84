#!/bin/sh
# fault.sh - one rank of a 4-process storm dies (kill: SIGKILL mid-run) or exits early
# (exit: status 3, without MPI_Finalize, while the others wait for it). The job must
# end within 10 s, with a non-zero status and a message naming the rank.
# usage: fault.sh kill|exit TEST_MPI_STORM "MPIEXEC -n 4 [flags]"
mode=$1 prog=$2 launch=$3
case $mode in
kill) args="--kill-rank 2" rank=2 ;;
exit) args="--exit-rank 1" rank=1 ;;
*) echo "fault.sh: unknown mode '$mode'"; exit 2 ;;
esac
out=$(mktemp)
start=$(date +%s%N)
# shellcheck disable=SC2086
timeout 60 $launch "$prog" --workers 2 --seeds 20 $args >"$out" 2>&1
rc=$?
end=$(date +%s%N)
ms=$(( (end - start) / 1000000 ))
cat "$out"
echo "fault.sh: $mode: status $rc after $ms ms"
fail=0
[ "$rc" -ne 0 ] || { echo "fault.sh: FAIL: the job succeeded although rank $rank failed"; fail=1; }
[ "$rc" -ne 124 ] || { echo "fault.sh: FAIL: the job hung (killed by timeout)"; fail=1; }
[ "$ms" -le 10000 ] || { echo "fault.sh: FAIL: took $ms ms, more than 10 s"; fail=1; }
# Open MPI's mpirun names the rank ("process rank 2 ... exited on signal 9"). MPICH's
# Hydra does not: its "BAD TERMINATION" banner gives the pid of the node's first process
# and the signal, so there we can only require the cause.
if grep -q "BAD TERMINATION" "$out" && [ "$mode" = kill ]; then
    grep -Eqi "signal:? 9|killed" "$out" || { echo "fault.sh: FAIL: no message names the cause"; fail=1; }
    echo "fault.sh: note: the launcher (MPICH Hydra) names no rank for a killed process"
elif ! grep -Eqi "rank $rank([^0-9]|\$)" "$out"; then
    echo "fault.sh: FAIL: no message names rank $rank"
    fail=1
fi
rm -f "$out"
exit $fail
