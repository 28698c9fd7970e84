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
# And failures inside the applications' own set-up, before or between the library's
# collective steps (which used to end the job with status 15 or hang it; each now ends
# in vw_config_agree or vw_world_agree):
#   * a scene that differs on ranks 1 and up (one sphere 2e-62 across, a sphere beyond
#     the ray tracer's coordinate limit), for render and animate: another scene
#     (vw_cli_same_scene); memory for the job on rank 1 alone (job-nomem, rt_job_create);
#     with NP 3, ranks 1 and 2 both fail and the message is rank 1's; memory for a part of
#     the scene's records on rank 1 alone (job-records-nomem, between the world's steps);
#   * memory, by the test switch VW_FAULT: for the image sums, which rank 0 alone keeps
#     (job-accum-nomem); on rank 1 alone for the mapping (map-nomem, rt_job_map), the
#     farming (farm-nomem, rt_job_farm), animate's records (anim-nomem, rt_anim_create),
#     the radiosity solver before its world exists (solver-nomem) and after it
#     (solver-slots-nomem, rad_solver_create); during its solve, in a handler on rank 1
#     (solve-nomem: vw_ctx_fail fails the run on every rank) and in the output handlers
#     collecting the solution on rank 0 (collect-nomem).
# And memory that rank 1 alone lacks between the collective steps of a balance or of a
# frame's edits (which hung the job: the others waited in the next step): render
# --balance tensor (rt_job_balance: its loads balance-nomem, a rebuild of the cells
# balance-rebuild-nomem, the saved layout balance-layout-nomem; vw_balance_world's plan
# balance-plan-nomem, and with --balance duplicate its copies' balance-copies-nomem),
# animate's edits
# (rt_anim_apply: the touched cells' marks anim-apply-nomem, room for an added object's
# records anim-records-nomem) and its rebalance between frames (rt_anim_balance:
# anim-balance-nomem); and inside vw_dynscene_apply, a batch's probes and pending edits
# (dynscene-batch-nomem), the room for its accepted edits (dynscene-commit-nomem) and the
# collider's contacts (collider-contacts-nomem: the query fails on every rank alike),
# each agreed before the collider's next collective step.
# usage: rank_status.sh VWALLS NP "MPIEXEC -n NP [flags]"
vwalls=$1 np=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
"$vwalls" gen cornell -o "$dir/cornell.nff" || { echo "rank_status.sh: FAIL: gen cornell"; exit 1; }
"$vwalls" gen balls --size 1 -o "$dir/balls.nff" || { echo "rank_status.sh: FAIL: gen balls"; exit 1; }
printf 'move 0 0.01 0 0\nframe\n' >"$dir/edits"
# an added sphere at the first sphere's centre: a contact for the collider to record
# shellcheck disable=SC2046
set -- $(grep -m1 '^s ' "$dir/balls.nff")
printf 'check on\nadd sphere %s %s %s 0.05\nframe\n' "$2" "$3" "$4" >"$dir/hit"
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

# The applications' set-up. Ranks 1 and up read tiny1.nff, rank 0 tiny0.nff.
ge1="[ $rank -ge 1 ] && n=1 || n=0"
{ sed -n '1,/^f /p' "$dir/balls.nff"; echo "s 0 0 0 1e-62"; } >"$dir/tiny1.nff"
cp "$dir/balls.nff" "$dir/tiny0.nff"
grep -q "^s 0 0 0 1e-62" "$dir/tiny1.nff" && grep -q "^v" "$dir/tiny1.nff" ||
    { echo "FAIL: could not make tiny1.nff"; fail=1; }
rm -f "$dir/r.png"
# Since the scenes are compared (vw_cli_same_scene), a scene the ray tracer refuses on
# ranks 1 and up alone is stopped as another scene; rt_job_create's own agreement is
# reached by memory rank 1 alone lacks for the job (job-nomem).
must_agree "render, a scene too small for the ray tracer on ranks 1 and up" 2 \
    "^vwalls render: rank 1: was given another scene than rank 0" \
    "$ge1; \"$vwalls\" render \"$dir/tiny\$n.nff\" -o \"$dir/r.png\" $small"
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, tiny scene: output written"; fail=1; }
must_agree "animate, a scene too small for the ray tracer on ranks 1 and up" 2 \
    "^vwalls animate: rank 1: was given another scene than rank 0" \
    "$ge1; \"$vwalls\" animate \"$dir/tiny\$n.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" $small"
{ cat "$dir/balls.nff"; echo "s 2e37 0 0 1"; } >"$dir/far1.nff"
cp "$dir/balls.nff" "$dir/far0.nff"
must_agree "render, a sphere beyond the coordinate limit on ranks 1 and up" 2 \
    "^vwalls render: rank 1: was given another scene than rank 0" \
    "$ge1; \"$vwalls\" render \"$dir/far\$n.nff\" -o \"$dir/r.png\" $small"
for c in render animate; do
    [ $c = render ] && args="-o \"$dir/r.png\"" || args="\"$dir/edits\" -o \"$dir/a%d.png\""
    must_agree "$c, no memory for the job on rank 1" 1 "^vwalls $c: rank 1: out of memory" \
        "[ $rank = 1 ] && export VW_FAULT=job-nomem; \"$vwalls\" $c \"$dir/balls.nff\" $args $small"
done
# The scene's records are converted a part at a time between the world's collective
# steps: rank 1 alone without room for a part stops every rank there.
must_agree "render, no memory for the scene's records on rank 1" 1 \
    "^vwalls render: rank 1: the scene's records: out of memory" \
    "[ $rank = 1 ] && export VW_FAULT=job-records-nomem; \"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" $small"
must_agree "render, no memory for the image sums (rank 0 alone keeps them)" 1 \
    "^vwalls render: rank 0: out of memory for the 32x32 image" \
    "VW_FAULT=job-accum-nomem \"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" $small"
for f in map farm; do
    [ $f = map ] && what="mapping the cells" || what="farming the cells"
    must_agree "render, no memory for $what on rank 1" 1 "^vwalls render: rank 1: $what: out of memory" \
        "[ $rank = 1 ] && export VW_FAULT=$f-nomem; \"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --map greedy $small"
done
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, no memory: output written"; fail=1; }
must_agree "animate, no memory for the records on rank 1" 1 \
    "^vwalls animate: rank 1: out of memory for the scene's records" \
    "[ $rank = 1 ] && export VW_FAULT=anim-nomem; \"$vwalls\" animate \"$dir/balls.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" $small"
for f in solver solver-slots; do
    [ $f = solver ] && what="the radiosity solver" || what="the radiosity world"
    must_agree "radiosity, no memory for $what on rank 1" 1 \
        "^vwalls radiosity: rank 1: cannot set up $what: out of memory" \
        "[ $rank = 1 ] && export VW_FAULT=$f-nomem; \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/l.ply\" --cells 2x2x2 --workers 1 --max-shots 4 --quiet"
done
must_agree "radiosity, no memory in a handler of the solve on rank 1" 1 \
    "^vwalls radiosity: radiosity run failed: rank 1: cell [0-9]*: out of memory ([0-9]* bytes) in the solve" \
    "[ $rank = 1 ] && export VW_FAULT=solve-nomem; \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/l.ply\" --cells 2x2x2 --workers 1 --max-shots 40 --quiet"
must_agree "radiosity, no memory for the collected solution (rank 0 alone collects it)" 1 \
    "^vwalls radiosity: radiosity run failed: rank 0: out of memory ([0-9]* bytes) collecting the solution" \
    "VW_FAULT=collect-nomem \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/l.ply\" --cells 2x2x2 --workers 1 --max-shots 40 --quiet"
[ ! -e "$dir/l.ply" ] || { echo "FAIL: radiosity, no memory: output written"; fail=1; }

# Balancing and editing, rank 1 short of memory between collective steps.
on1="[ $rank = 1 ] && export VW_FAULT"
for f in balance balance-rebuild balance-layout; do
    case $f in
    balance) what="balancing: the loads" ;;
    balance-rebuild) what="rebuilding the cells" ;;
    balance-layout) what="saving the layout" ;;
    esac
    must_agree "render --balance tensor, no memory for $f on rank 1" 1 \
        "^vwalls render: rank 1: $what: out of memory" \
        "$on1=$f-nomem; \"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --balance tensor $small"
done
for f in plan copies; do
    [ $f = plan ] && b=tensor || b=duplicate
    must_agree "render --balance $b, no memory for the balancer's $f on rank 1" 1 \
        "^vwalls render: balancing: rank 1: vw_balance_world: out of memory" \
        "$on1=balance-$f-nomem; \"$vwalls\" render \"$dir/balls.nff\" -o \"$dir/r.png\" --balance $b $small"
done
[ ! -e "$dir/r.png" ] || { echo "FAIL: render --balance, no memory: output written"; fail=1; }
printf 'check off\nadd sphere 0 0 0 0.05\nframe\n' >"$dir/adds"
for f in anim-apply anim-records; do
    [ $f = anim-apply ] && e=edits || e=adds
    must_agree "animate, no memory for the edits' $f bookkeeping on rank 1" 1 \
        "^vwalls animate: rank 1: applying edits: out of memory for the marks and records" \
        "$on1=$f-nomem; \"$vwalls\" animate \"$dir/balls.nff\" \"$dir/$e\" -o \"$dir/a%d.png\" $small"
done
for f in batch commit; do
    [ $f = batch ] && what="preparing a batch of edits" || what="deciding a batch of edits"
    must_agree "animate, no memory for the dynamic scene's $f on rank 1" 1 \
        "^vwalls animate: rank 1: applying edits: $what: out of memory" \
        "$on1=dynscene-$f-nomem; \"$vwalls\" animate \"$dir/balls.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" $small"
done
must_agree "animate, no room for the collider's contacts on rank 1" 1 \
    "^vwalls animate: rank 1: applying edits: checking a batch of edits for collisions: cell [0-9]*: out of memory for 64 contacts" \
    "$on1=collider-contacts-nomem; \"$vwalls\" animate \"$dir/balls.nff\" \"$dir/hit\" -o \"$dir/a%d.png\" $small"
must_agree "animate --balance tensor, no memory for the rebalance on rank 1" 1 \
    "^vwalls animate: rank 1: balancing: the loads: out of memory" \
    "$on1=anim-balance-nomem; \"$vwalls\" animate \"$dir/balls.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" --balance tensor --threshold 0 --trigger work $small"
exit $fail
