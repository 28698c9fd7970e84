#!/bin/sh
# resume_rank0.sh - vwalls radiosity --resume under MPI reads the checkpoint on rank 0
# alone, the process that wrote it, and hands it to the others:
#   * a checkpoint that only rank 0's host has (hosts without a shared file system: each
#     rank runs in a directory of its own) resumes; it used to stop every rank with
#     "rank 1: ck: cannot open checkpoint";
#   * another rank's stale copy (an older checkpoint of the same run) is not read; it
#     used to be, and that rank resumed from another state than rank 0's, which only the
#     energy ledger at the end of the whole solve found ("energy ledger off by 0.04:
#     no output written", status 1);
#   * a checkpoint rank 0 lacks still stops every rank, naming rank 0, with no output.
# Every job must end within 60 s.
# usage: resume_rank0.sh VWALLS "MPIEXEC -n NP [flags]"
vwalls=$1 launch=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
common="--cells 2x2x2 --workers 1 --quiet"
# shellcheck disable=SC2016 # expanded by each rank's sh, not here
rank='${OMPI_COMM_WORLD_RANK:-$PMI_RANK}'

"$vwalls" gen cornell -o "$dir/cornell.nff" || { echo "FAIL: gen cornell"; exit 1; }
# Each rank's own directory ("host") with its own copy of the scene.
for r in 0 1 2 3 4 5 6 7; do
    mkdir "$dir/h$r" && cp "$dir/cornell.nff" "$dir/h$r/" || exit 1
done
# Two checkpoints of one run, after 2 and after 5 rounds, by the threads engine.
for n in 2 5; do
    # shellcheck disable=SC2086
    "$vwalls" radiosity "$dir/cornell.nff" $common --max-rounds $n --checkpoint "$dir/ck$n" ||
        { echo "FAIL: writing the checkpoint of $n rounds: status $?"; exit 1; }
done
cmp -s "$dir/ck2" "$dir/ck5" && { echo "FAIL: the two checkpoints are the same"; exit 1; }

# run NAME WANT_STATUS PATTERN: the resume under the launcher, each rank in its
# directory, within 60 s; the outputs go to $dir/out.*.
run() {
    name=$1 want=$2 pattern=$3
    rm -f "$dir"/out.*
    # shellcheck disable=SC2086
    timeout 60 $launch sh -c "cd \"$dir/h$rank\" && exec \"$vwalls\" radiosity cornell.nff $common \
        --resume ck --csv \"$dir/out.csv\" --stats \"$dir/out.json\"" >"$dir/log" 2>&1
    rc=$?
    if [ "$rc" -eq 124 ]; then
        echo "FAIL: $name: the job hung (killed after 60 s)"
    elif [ "$rc" -ne "$want" ]; then
        echo "FAIL: $name: status $rc, expected $want"
    elif [ -n "$pattern" ] && ! grep -Eq "$pattern" "$dir/log"; then
        echo "FAIL: $name: no message matching '$pattern'"
    else
        echo "ok: $name (status $rc)"
        return 0
    fi
    sed 's/^/    /' "$dir/log"
    fail=1
    return 1
}

# converged JSON: the solve converged, its ledger holds, and it went on from the
# checkpoint's shots (the stats count the shots of the whole solve).
converged() {
    python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["radiosity"]
print(f"  {r['shots']} shots, energy error {r['energy_error']:.2e}, converged {r['converged']}")
sys.exit(0 if r["converged"] and abs(r["energy_error"]) <= 1e-9 else 1)
PY
}

cp "$dir/ck2" "$dir/h0/ck"
if run "checkpoint on rank 0's host alone" 0 ""; then
    converged "$dir/out.json" || { echo "FAIL: checkpoint on rank 0 alone: $(cat "$dir/out.json")"; fail=1; }
fi

for r in 1 2 3 4 5 6 7; do cp "$dir/ck5" "$dir/h$r/ck"; done
if run "an older checkpoint on the other ranks' hosts" 0 ""; then
    converged "$dir/out.json" || { echo "FAIL: stale copies: $(cat "$dir/out.json")"; fail=1; }
fi

rm "$dir/h0/ck"
if run "no checkpoint on rank 0's host" 2 "rank 0: ck: cannot open checkpoint"; then
    if [ -e "$dir/out.csv" ] || [ -e "$dir/out.json" ]; then
        echo "FAIL: no checkpoint on rank 0: output written"
        fail=1
    fi
fi
exit $fail
