#!/bin/sh
# fault.sh - one rank of a 4-process storm dies (kill: SIGKILL mid-run), exits early
# (exit: status 3, without MPI_Finalize, while the others wait for it) or hangs while
# alive (hang: a handler that never returns). The job must end within 10 s (beyond what
# a job of the same processes takes to start MPI and end it), with a non-zero
# status and a message naming the rank; a hung rank sends no such message (nothing has
# failed), so that job must end by the launcher's time limit (MPIEXEC_TIMEOUT, honoured
# by Open MPI's mpirun and MPICH's Hydra alike), saying so.
# usage: fault.sh kill|exit|hang TEST_STORM "MPIEXEC -n 4 [flags]"
mode=$1 prog=$2 launch=$3
case $mode in
kill) args="--kill-rank 2" rank=2 ;;
exit) args="--exit-rank 1" rank=1 ;;
hang) args="--hang-rank 1" rank=1 ;;
*) echo "fault.sh: unknown mode '$mode'"; exit 2 ;;
esac
. "$(dirname "$0")/must_fail.sh"
# shellcheck disable=SC2086
base_ms=$(startup_ms $launch "$prog" --seeds 0)
if [ "$mode" = hang ]; then
    export MPIEXEC_TIMEOUT=$((4 + (base_ms + 999) / 1000))
    # shellcheck disable=SC2086
    must_fail "fault.sh: $mode" 10 60 $launch "$prog" --workers 2 --seeds 20 $args
    grep -q "rank 1 hangs on purpose" "$out" || { echo "fault.sh: FAIL: rank 1 did not hang"; fail=1; }
    grep -Eqi "time limit|timed out" "$out" ||
        { echo "fault.sh: FAIL: the launcher did not say the time limit ended the job"; fail=1; }
    rm -f "$out"
    exit $fail
fi
# shellcheck disable=SC2086
must_fail "fault.sh: $mode" 10 60 $launch "$prog" --workers 2 --seeds 20 $args
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
