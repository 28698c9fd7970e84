#!/bin/sh
# rank_status.sh - a run that fails on the output process alone ends with the same
# non-zero status on every rank, within 30 s, and says why once. Only rank 0 writes the
# outputs (and checks some results: radiosity's energy ledger), so it alone may fail at
# the end: it exited 1 and the other ranks 0, and whatever read another rank's status
# (a batch system, a script run by each rank) took the failed run for a success. Every
# command: render (-o, --stats, --overlay), animate and edit (--stats), gen (-o, stdout),
# info (stdout), example-pairs and example-components (--stats), radiosity (the ledger,
# forced by the test switch VW_FAULT=ledger). Standard output into /dev/full is rank 0's
# alone: the others' goes to /dev/null. And a failure of another rank alone: all exit
# with its status, and rank 0 names it.
# usage: rank_status.sh VWALLS NP "MPIEXEC -n NP [flags]"
vwalls=$1 np=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
"$vwalls" gen cornell -o "$dir/cornell.nff" || { echo "rank_status.sh: FAIL: gen cornell"; exit 1; }
"$vwalls" gen balls --size 1 -o "$dir/balls.nff" || { echo "rank_status.sh: FAIL: gen balls"; exit 1; }
printf 'move 0 0.01 0 0\nframe\n' >"$dir/edits"
# (expanded by each rank's shell, not here)
# shellcheck disable=SC2016
rank='${OMPI_COMM_WORLD_RANK:-$PMI_RANK}'
missing="$dir/nodir"
small="--size 32x32 --cells 2x2x2 --workers 1 --quiet"

# must_agree NAME WANT PATTERN SHELL_COMMAND: each rank's shell runs SHELL_COMMAND,
# prints its status and exits 0 itself (a launcher ends the other ranks of a job once
# one exits non-zero, and would cut off their lines). Every rank must report status
# WANT within 30 s, and the message matching PATTERN must come once, not once a rank.
must_agree() {
    name=$1 want=$2 pattern=$3 cmd=$4
    start=$(date +%s%N)
    # shellcheck disable=SC2086
    timeout 40 $launch sh -c "$cmd; echo \"rank_status: rank $rank: status \$?\"" \
        <"$dir/edits" >"$dir/out" 2>&1
    rc=$?
    ms=$(( ($(date +%s%N) - start) / 1000000 ))
    bad=0
    [ "$rc" -ne 124 ] || { echo "FAIL: $name: the job hung (killed by timeout)"; bad=1; }
    [ "$ms" -le 30000 ] || { echo "FAIL: $name: took $ms ms, more than 30 s"; bad=1; }
    n=$(grep -c -- "$pattern" "$dir/out")
    [ "$n" -eq 1 ] || { echo "FAIL: $name: $n messages matching '$pattern', not 1"; bad=1; }
    r=0
    while [ "$r" -lt "$np" ]; do
        s=$(sed -n "s/^rank_status: rank $r: status \([0-9]*\)\$/\1/p" "$dir/out")
        if [ -z "$s" ]; then
            echo "FAIL: $name: rank $r reported no status"
            bad=1
        elif [ "$s" -ne "$want" ]; then
            echo "FAIL: $name: rank $r exited $s, not $want (the failed run's status)"
            bad=1
        fi
        r=$((r + 1))
    done
    if [ "$bad" -eq 0 ]; then
        echo "ok: $name (job status $rc after $ms ms)"
    else
        sed 's/^/    /' "$dir/out"
        fail=1
    fi
}

must_agree "radiosity, the energy ledger off" 1 "energy ledger off by inf" \
    "VW_FAULT=ledger \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/l.ply\" \
     --cells 2x2x2 --workers 1 --max-shots 4 --quiet"
[ ! -e "$dir/l.ply" ] || { echo "FAIL: radiosity: output written"; fail=1; }
must_agree "render -o into a missing directory" 1 "nodir/r.png" \
    "\"$vwalls\" render \"$dir/balls.nff\" -o \"$missing/r.png\" $small"
must_agree "render --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --stats \"$missing/s.json\" $small"
must_agree "render --overlay into a missing directory" 1 "nodir/o.png" \
    "\"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --overlay \"$missing/o.png\" $small"
must_agree "render --map greedy --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --map greedy --stats \"$missing/s.json\" $small"
must_agree "animate --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" animate \"$dir/balls.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" --stats \"$missing/s.json\" $small"
must_agree "edit --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" edit \"$dir/balls.nff\" --stats \"$missing/s.json\" $small"
must_agree "gen -o into a missing directory" 1 "nodir/g.nff" \
    "\"$vwalls\" gen balls --size 1 -o \"$missing/g.nff\""
must_agree "gen to a full stdout" 1 "cannot write to standard output" \
    "\"$vwalls\" gen balls --size 1 >/dev/full"
must_agree "info to a full stdout" 1 "cannot write to standard output" \
    "\"$vwalls\" info \"$dir/balls.nff\" >/dev/full"
must_agree "example-pairs --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" example-pairs --spheres 300 --workers 1 --quiet --stats \"$missing/s.json\""
must_agree "example-components --stats into a missing directory" 1 "nodir/s.json" \
    "\"$vwalls\" example-components --spheres 300 --workers 1 --quiet --stats \"$missing/s.json\""
# A failure of another process than the output one (here a scene only rank 0 has, which
# info reads on every process): all exit with its status, and the output process says
# why (rank 1's message: info's ranks agree on the scene, as every command's do).
cp "$dir/balls.nff" "$dir/balls0.nff"
must_agree "info, the scene missing on rank 1" 2 "rank 1: .*balls1.nff" \
    "\"$vwalls\" info \"$dir/balls$rank.nff\" >/dev/null"
exit $fail
