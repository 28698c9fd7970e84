#!/bin/sh
# rank_alone.sh - a check that fails on one rank alone, before a collective call the
# others go on to, stops every rank (the failing one used to return to the job's final
# agreement while the others waited for it in the next collective call: a hang):
#   * a camera override that is bad only against one host's copy of the scene (--at at
#     that copy's eye);
#   * memory for --speeds that one rank lacks (VW_FAULT=speeds-nomem there alone);
#   * memory for --overlay-by worker's map, kept by rank 0 alone (VW_FAULT=eye-workers-nomem),
#     and for --overlay's map of the cells where eye rays hit (VW_FAULT=hit-cells-nomem);
#   * a radiosity --image larger than allowed by one host's copy of the scene;
#   * memory for the spheres of example-pairs and example-components on rank 1
#     (VW_FAULT=spheres-nomem), for animate's frame records (VW_FAULT=frames-nomem).
# Each job ends within 30 s with the single process's status and the failing rank's
# message, printed once.
# usage: rank_alone.sh VWALLS SCENE "MPIEXEC -n 2 [flags]"
vwalls=$1 scene=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
common="--size 48x48 --cells 2x2x2 --workers 1"

# run NAME WANT_STATUS PATTERN args...: under the launcher, within 30 s; PATTERN on
# exactly one line of the output.
run() {
    name=$1 want=$2 pattern=$3
    shift 3
    # shellcheck disable=SC2086
    timeout 30 $launch "$@" </dev/null >"$dir/out" 2>&1
    rc=$?
    if [ "$rc" -eq 124 ]; then
        echo "FAIL: $name: the job hung (killed after 30 s)"
    elif [ "$rc" -ne "$want" ]; then
        echo "FAIL: $name: status $rc, expected $want"
    elif [ "$(grep -Ec "$pattern" "$dir/out")" -ne 1 ]; then
        echo "FAIL: $name: not one line matching '$pattern'"
    else
        echo "ok: $name (status $rc)"
        return 0
    fi
    fail=1
    sed 's/^/    /' "$dir/out"
    return 1
}

# Rank 1 reads s1.nff, the others s0.nff, ...
rank='${OMPI_COMM_WORLD_RANK:-$PMI_RANK}'
cp "$scene" "$dir/s0.nff"
sed 's/^from [-0-9.e ]*/from 9 9 9 /' "$scene" >"$dir/s1.nff"
cmp -s "$scene" "$dir/s1.nff" && { echo "FAIL: $scene has no 'from' line"; fail=1; }
run "render, --at at the eye of rank 1's scene" 2 \
    "^vwalls render: rank 1: --from/--at/--up: 'from' and 'at' are the same point" \
    sh -c "exec \"$vwalls\" render \"$dir/s$rank.nff\" -o \"$dir/r.png\" --at 9,9,9 $common"
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, --at: output written"; fail=1; }

run "render, no memory for --speeds on rank 1" 1 \
    "^vwalls render: rank 1: out of memory for --speeds" \
    sh -c "[ $rank = 1 ] && export VW_FAULT=speeds-nomem; exec \"$vwalls\" render \"$scene\" -o \"$dir/r.png\" --speeds 1,1 $common"

run "render, no memory for the worker map (rank 0 alone keeps it)" 1 \
    "^vwalls render: rank 0: out of memory for the overlay's worker map" \
    env VW_FAULT=eye-workers-nomem "$vwalls" render "$scene" -o "$dir/r.png" --overlay "$dir/o.png" \
    --overlay-by worker $common
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, worker map: output written"; fail=1; }
run "render, no memory for the hit-cell map (rank 0 alone keeps it)" 1 \
    "^vwalls render: rank 0: out of memory for the overlay's cell map" \
    env VW_FAULT=hit-cells-nomem "$vwalls" render "$scene" -o "$dir/r.png" --overlay "$dir/o.png" $common
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, hit-cell map: output written"; fail=1; }

"$vwalls" gen cornell -o "$dir/c0.nff" || fail=1
sed 's/^resolution .*/resolution 20000 20000/' "$dir/c0.nff" >"$dir/c1.nff"
run "radiosity --image, a picture too large for rank 1's scene" 2 \
    "^vwalls radiosity: rank 1: --image: picture size 20000x20000 too large" \
    sh -c "exec \"$vwalls\" radiosity \"$dir/c$rank.nff\" -o \"$dir/rad.ply\" --image \"$dir/rad.png\" --cells 2x2x2 --workers 1 --max-shots 8 --quiet"
[ ! -e "$dir/rad.ply" ] || { echo "FAIL: radiosity --image: output written"; fail=1; }

for ex in pairs components; do
    run "example-$ex, no memory for the spheres on rank 1" 1 \
        "^vwalls example-$ex: rank 1: out of memory for 500 spheres" \
        sh -c "[ $rank = 1 ] && export VW_FAULT=spheres-nomem; exec \"$vwalls\" example-$ex --spheres 500 --workers 1"
done
printf 'move 0 0.01 0 0\nframe\nmove 1 0 0.01 0\nframe\n' >"$dir/edits"
run "animate, no memory for the frame records on rank 1" 1 \
    "^vwalls animate: rank 1: frame 0: out of memory" \
    sh -c "[ $rank = 1 ] && export VW_FAULT=frames-nomem; exec \"$vwalls\" animate \"$scene\" \"$dir/edits\" -o \"$dir/a%d.png\" $common"
exit $fail
