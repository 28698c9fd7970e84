#!/bin/sh
# rank_input.sh - input and output that only some ranks have never leave a rank waiting:
#   * vwalls edit reads stdin, which the launcher gives rank 0 alone: every rank must
#     apply the same edits (same log and frames as the single process's);
#   * vwalls animate's edit script is rank 0's, read there and handed to every rank, so
#     a script that differs (or is missing) on another rank changes nothing;
#   * a scene missing on one rank stops every rank, naming it; a bad one keeps its
#     "FILE:LINE: " first, the rank after it; and
#     another --workers, --depth, camera or scene (a material) on one rank is named as
#     such, and so is
#     another radiosity option that changes the solution (--sf, --hemicube, ...);
#   * gen -o is written by rank 0 alone, and warnings about a scene come from rank 0;
#   * an output only rank 0 writes (animate's frames, --log, gen -o) into a missing directory,
#     or a radiosity snapshot on a full disk, stops every rank with the single
#     process's status.
# Every job must end within 30 s.
# usage: rank_input.sh VWALLS SCENE "MPIEXEC -n 2 [flags]"
vwalls=$1 scene=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
common="--size 48x48 --cells 2x2x2 --workers 1"
printf 'move 0 0.01 0 0\nframe\nbogus\nmove 1 0 0.01 0\nframe\n' >"$dir/edits"
cp "$scene" "$dir/s0.nff"
cp "$dir/edits" "$dir/e0.txt"

# run NAME WANT_STATUS GREP_PATTERN args... : under the launcher, within 30 s
run() {
    name=$1 want=$2 pattern=$3
    shift 3
    # shellcheck disable=SC2086
    timeout 30 $launch "$@" <"$dir/edits" >"$dir/out" 2>&1
    rc=$?
    if [ "$rc" -eq 124 ]; then
        echo "FAIL: $name: the job hung (killed after 30 s)"
        fail=1
    elif [ "$rc" -ne "$want" ]; then
        echo "FAIL: $name: status $rc, expected $want"
        fail=1
    elif [ -n "$pattern" ] && ! grep -Eq "$pattern" "$dir/out"; then
        echo "FAIL: $name: no message matching '$pattern'"
        fail=1
    else
        echo "ok: $name (status $rc)"
        return 0
    fi
    sed 's/^/    /' "$dir/out"
    return 1
}

# edit: stdin reaches every rank through rank 0.
mkdir "$dir/f1" "$dir/fm"
# shellcheck disable=SC2086
"$vwalls" edit "$scene" -o "$dir/f1/%d.png" --log "$dir/log1" $common <"$dir/edits" >/dev/null 2>&1
want=$?
# shellcheck disable=SC2086
if run "edit from stdin" "$want" "" "$vwalls" edit "$scene" -o "$dir/fm/%d.png" --log "$dir/logm" $common; then
    cmp "$dir/log1" "$dir/logm" || { echo "FAIL: edit: the logs differ"; fail=1; }
    for f in 0 1; do
        cmp "$dir/f1/$f.png" "$dir/fm/$f.png" || { echo "FAIL: edit: frame $f differs"; fail=1; }
    done
fi

# A file only rank 0 has (the others look for s1.nff, e1.txt, ...).
rank='${OMPI_COMM_WORLD_RANK:-$PMI_RANK}'
wrank='$(('"$rank"' + 1))'
# shellcheck disable=SC2086
run "render, scene missing on rank 1" 2 "rank 1: .*s1.nff" \
    sh -c "exec \"$vwalls\" render \"$dir/s$rank.nff\" -o \"$dir/r.png\" $common"
# shellcheck disable=SC2086
run "animate, scene missing on rank 1" 2 "rank 1: .*s1.nff" \
    sh -c "exec \"$vwalls\" animate \"$dir/s$rank.nff\" \"$dir/edits\" -o \"$dir/a%d.png\" $common"
# Bad input keeps its "FILE:LINE: " first on the line, as without MPI, with the rank
# that failed after it (it used to come first: "rank 0: b0.nff:8: ...").
{ cat "$scene"; printf 'zzz 1 2 3\n'; } >"$dir/b0.nff"
badline=$(wc -l <"$dir/b0.nff")
cp "$scene" "$dir/c0.nff"
cp "$dir/b0.nff" "$dir/c1.nff"
# shellcheck disable=SC2086
run "render, a bad scene on every rank" 2 "^[^ ]*b0\.nff:$badline: rank 0: unknown keyword 'zzz'" \
    "$vwalls" render "$dir/b0.nff" -o "$dir/r.png" $common
# shellcheck disable=SC2086
run "render, a bad scene on rank 1 alone" 2 "^[^ ]*c1\.nff:$badline: rank 1: unknown keyword 'zzz'" \
    sh -c "exec \"$vwalls\" render \"$dir/c$rank.nff\" -o \"$dir/r.png\" $common"
[ ! -e "$dir/r.png" ] || { echo "FAIL: render of a bad scene wrote its image"; fail=1; }
# The edit script is rank 0's: the others' copies are not read, so one missing there
# is no error, and one missing on rank 0 is named as such.
# shellcheck disable=SC2086
run "animate, edits on rank 0 alone" 2 "e0.txt:3: " \
    sh -c "exec \"$vwalls\" animate \"$scene\" \"$dir/e$rank.txt\" -o \"$dir/a%d.png\" $common"
# shellcheck disable=SC2086
run "animate, edits missing on rank 0" 2 "rank 0: .*e1.txt" \
    sh -c "exec \"$vwalls\" animate \"$scene\" \"$dir/e$wrank.txt\" -o \"$dir/a%d.png\" $common"
# An edit script that differs between ranks, with a line bad on rank 1 alone: every
# rank runs rank 0's (rank 1 used to stop at its bad line while rank 0 waited for it
# in the next collective), so the frames are the single process's.
printf 'move 0 0.01 0 0\nframe\nmove 1 0 0.01 0\nframe\n' >"$dir/d0.txt"
printf 'move 0 0.01 0 0\nframe\nbogus\nmove 1 0 0.01 0\nframe\n' >"$dir/d1.txt"
mkdir "$dir/d1" "$dir/dm"
# shellcheck disable=SC2086
"$vwalls" animate "$scene" "$dir/d0.txt" -o "$dir/d1/%d.png" $common --quiet ||
  { echo "FAIL: animate $dir/d0.txt: status $?"; fail=1; }
# shellcheck disable=SC2086
if run "animate, an edit script bad on rank 1 alone" 0 "" \
    sh -c "exec \"$vwalls\" animate \"$scene\" \"$dir/d$rank.txt\" -o \"$dir/dm/%d.png\" $common --quiet"; then
    for f in 0 1; do
        cmp "$dir/d1/$f.png" "$dir/dm/$f.png" || { echo "FAIL: animate: frame $f differs"; fail=1; }
    done
fi

# A scene whose camera differs on rank 1, and another --depth there: each would draw
# another image (the world's check compares only cells and object bounds).
sed 's/^from [-0-9.e ]*/from 9 9 9 /' "$scene" >"$dir/s1.nff"
cmp -s "$scene" "$dir/s1.nff" && { echo "FAIL: $scene has no 'from' line"; fail=1; }
# shellcheck disable=SC2086
run "render, another camera on rank 1" 2 "rank 1: was given another view" \
    sh -c "exec \"$vwalls\" render \"$dir/s$rank.nff\" -o \"$dir/r.png\" $common"
run "animate, another --depth on rank 1" 2 "rank 1: was given another view" \
    sh -c "exec \"$vwalls\" animate \"$scene\" \"$dir/edits\" -o \"$dir/a%d.png\" --size 48x48 --cells 2x2x2 --depth $wrank"
rm "$dir/s1.nff"
# A scene whose first material differs on rank 1: the objects' bounds are the same, so the
# world's check passed, and the render drew (and the radiosity solved) wrongly without a
# word.
sed '0,/^f /s/^f [-0-9.e]*/f 0.123/' "$scene" >"$dir/s1.nff"
cmp -s "$scene" "$dir/s1.nff" && { echo "FAIL: $scene has no 'f' line"; fail=1; }
# shellcheck disable=SC2086
run "render, another material on rank 1" 2 "rank 1: was given another scene" \
    sh -c "exec \"$vwalls\" render \"$dir/s$rank.nff\" -o \"$dir/r.png\" $common"
[ ! -e "$dir/r.png" ] || { echo "FAIL: render, another material: output written"; fail=1; }
"$vwalls" gen cornell -o "$dir/c0.nff" || { echo "FAIL: gen cornell"; fail=1; }
sed '0,/^f /s/^f [-0-9.e]*/f 0.123/' "$dir/c0.nff" >"$dir/c1.nff"
run "radiosity, another material on rank 1" 2 "rank 1: was given another scene" \
    sh -c "exec \"$vwalls\" radiosity \"$dir/c$rank.nff\" -o \"$dir/l.ply\" --cells 2x2x2 --workers 1 --max-shots 4 --quiet"
[ ! -e "$dir/l.ply" ] || { echo "FAIL: radiosity, another material: output written"; fail=1; }
rm "$dir/s1.nff"

# Ranks given different worker counts: the message says so (not "invalid argument").
run "render, another worker count on rank 1" 2 "different worker counts" \
    sh -c "exec \"$vwalls\" render \"$scene\" -o \"$dir/r.png\" --size 48x48 --cells 2x2x2 --workers $wrank"
run "example-pairs, another worker count on rank 1" 1 "different worker counts" \
    sh -c "exec \"$vwalls\" example-pairs --spheres 500 --workers $wrank"
# Hosts of 2 and 3 cores (VW_CORES) without --workers: every process runs 2 workers, the
# fewest, so --speeds takes 2 x 2 numbers on both (rank 1 used to expect 6 and stop);
# a wrong count says where the count comes from.
cores='$(('"$rank"' + 2))'
run "render --speeds, hosts of 2 and 3 cores" 0 "" \
    sh -c "export VW_CORES=$cores; exec \"$vwalls\" render \"$scene\" -o \"$dir/r.png\" --size 48x48 --cells 2x2x2 --speeds 1,2,1,2 --quiet"
run "render --speeds, a wrong count on hosts of 2 and 3 cores" 2 \
    "expected 4 positive numbers, one per worker: 2 processes x 2 workers, the fewest cores of any process; --workers sets them" \
    sh -c "export VW_CORES=$cores; exec \"$vwalls\" render \"$scene\" -o \"$dir/r.png\" --size 48x48 --cells 2x2x2 --speeds 1,2,1,2,1,2 --quiet"

# Outputs into a missing directory: status 1, as the single process's (the frames'
# directory checked before any frame).
# shellcheck disable=SC2086
run "animate -o into a missing directory" 1 "nodir/%d.png: cannot write" \
    "$vwalls" animate "$scene" "$dir/edits" -o "$dir/nodir/%d.png" $common
# shellcheck disable=SC2086
run "animate --log into a missing directory" 1 "nodir/log" \
    "$vwalls" animate "$scene" "$dir/edits" -o "$dir/a%d.png" --log "$dir/nodir/log" $common
# Warnings about a scene every rank reads (an OBJ's missing material library): once,
# from rank 0, not once a rank.
warned=$(dirname "$scene")/../warn/obj_missing_mtl.obj
# shellcheck disable=SC2086
$launch "$vwalls" info "$warned" >/dev/null 2>"$dir/warn.err" || { echo "FAIL: info $warned: status $?"; fail=1; }
n=$(grep -c "warning: " "$dir/warn.err")
[ "$n" -eq 2 ] && echo "ok: scene warnings from rank 0 alone" ||
  { echo "FAIL: scene warnings: $n lines, want 2 (one a warning, from rank 0):"; sed 's/^/    /' "$dir/warn.err"; fail=1; }
# gen -o: rank 0 alone writes the file (every rank used to write it, each atomically);
# the others would write g1.nff, ... here. Into a missing directory: status 1.
run "gen -o, rank 0 alone writes" 0 "" \
    sh -c "exec \"$vwalls\" gen balls --size 1 -o \"$dir/g$rank.nff\""
[ -s "$dir/g0.nff" ] || { echo "FAIL: gen -o: rank 0 wrote no file"; fail=1; }
[ ! -e "$dir/g1.nff" ] || { echo "FAIL: gen -o: rank 1 wrote the file too"; fail=1; }
run "gen -o into a missing directory" 1 "nodir/g.nff" \
    "$vwalls" gen balls --size 1 -o "$dir/nodir/g.nff"
# A radiosity snapshot rank 0 cannot write (a full disk) stops every rank.
"$vwalls" gen cornell -o "$dir/cornell.nff"
run "radiosity, a snapshot that cannot be written" 1 "No space left" \
    "$vwalls" radiosity "$dir/cornell.nff" -o /dev/full --snapshot-every 20 --cells 2x2x2 --workers 1
# Radiosity options that change the solution, another on rank 1: status 2 naming the
# option, no output (the ranks used to agree on the cells alone and solve by different
# rules). The same options on both ranks still run.
for opt in "--sf:1e-\$((3 + $rank))" "--hemicube:\$((32 + 32 * $rank))" \
           "--elements:\$((2 + $rank))" "--subdivide:0.\$((3 + $rank))"; do
  oname=${opt%%:*} oval=${opt#*:}  # (run sets $name)
  rm -f "$dir/rad.ply"
  run "radiosity, another $oname on rank 1" 2 "rank 1: was given another $oname than rank 0" \
      sh -c "exec \"$vwalls\" radiosity \"$dir/cornell.nff\" -o \"$dir/rad.ply\" --cells 2x2x2 --workers 1 --max-shots 8 --quiet $oname $oval"
  [ ! -e "$dir/rad.ply" ] || { echo "FAIL: radiosity, another $oname on rank 1: output written"; fail=1; }
done
run "radiosity, the same options on every rank" 0 "" \
    "$vwalls" radiosity "$dir/cornell.nff" -o "$dir/rad.ply" --cells 2x2x2 --workers 1 --max-shots 8 \
    --quiet --sf 1e-4 --hemicube 32
exit $fail
