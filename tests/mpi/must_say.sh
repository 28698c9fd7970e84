#!/bin/sh
# must_say.sh - a job that must fail within 20 s, non-zero, with a line matching PATTERN
# (grep -E) in its output: another build (mpi_build_check), a malformed packet
# (mpi_wire_check) or turn request (mpi_turn_check) must stop the job with a message
# naming what is wrong and its sender.
# usage: must_say.sh NAME PATTERN PROGRAM [ARGS...] "MPIEXEC -n N [flags]"
name=$1 pattern=$2
shift 2
eval "launch=\${$#}"
n=$# i=1 cmd=""
for a in "$@"; do
    [ "$i" -lt "$n" ] && cmd="$cmd $a"
    i=$((i + 1))
done
. "$(dirname "$0")/must_fail.sh"
# shellcheck disable=SC2086
must_fail "$name" 20 30 $launch $cmd
grep -Eq "$pattern" "$out" || { echo "$name: FAIL: no line matching '$pattern'"; fail=1; }
rm -f "$out"
exit $fail
