#!/bin/sh
# rank_status.sh - a run that fails on the output process alone ends with the same
# non-zero status on every rank, within 30 s: vwalls radiosity whose energy ledger does
# not add up (forced by the test switch VW_FAULT=ledger; only rank 0 checks the ledger)
# exited 1 on rank 0 and 0 on the others, so whatever read another rank's status (a
# batch system, a script run by each rank) took the failed run for a success.
# usage: rank_status.sh VWALLS NP "MPIEXEC -n NP [flags]"
vwalls=$1 np=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$vwalls" gen cornell -o "$dir/cornell.nff" || { echo "rank_status.sh: FAIL: gen cornell"; exit 1; }
# (expanded by each rank's shell, not here)
# shellcheck disable=SC2016
rank='${OMPI_COMM_WORLD_RANK:-$PMI_RANK}'
# Each rank's shell prints its vwalls' status and exits 0 itself: a launcher ends the
# other ranks of a job once one exits non-zero, and would cut off their lines.
start=$(date +%s%N)
# shellcheck disable=SC2086
timeout 60 $launch sh -c "VW_FAULT=ledger \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/l.ply\" \
  --cells 2x2x2 --workers 1 --max-shots 4 --quiet; echo \"rank_status: rank $rank: status \$?\"" \
  >"$dir/out" 2>&1
rc=$?
ms=$(( ($(date +%s%N) - start) / 1000000 ))
cat "$dir/out"
echo "rank_status.sh: job status $rc after $ms ms"
fail=0
[ "$rc" -ne 124 ] || { echo "rank_status.sh: FAIL: the job hung (killed by timeout)"; fail=1; }
[ "$ms" -le 30000 ] || { echo "rank_status.sh: FAIL: took $ms ms, more than 30 s"; fail=1; }
grep -q "energy ledger off by inf" "$dir/out" ||
    { echo "rank_status.sh: FAIL: no message about the ledger"; fail=1; }
[ ! -e "$dir/l.ply" ] || { echo "rank_status.sh: FAIL: output written"; fail=1; }
r=0
while [ "$r" -lt "$np" ]; do
    s=$(sed -n "s/^rank_status: rank $r: status \([0-9]*\)\$/\1/p" "$dir/out")
    if [ -z "$s" ]; then
        echo "rank_status.sh: FAIL: rank $r reported no status"
        fail=1
    elif [ "$s" -ne 1 ]; then
        echo "rank_status.sh: FAIL: rank $r exited $s, not 1 (the failed run's status)"
        fail=1
    fi
    r=$((r + 1))
done
exit $fail
