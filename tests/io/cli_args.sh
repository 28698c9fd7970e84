#!/bin/sh
# cli_args.sh VWALLS TMPDIR - options and outputs refused before any work, the review's
# cases: an output naming an input or another output (status 2, nothing written, the
# input intact; devices exempt); an output into a missing directory found before the
# work (gen -o, --log, the examples' --stats); gen --cluster for balls, and an unknown
# gen scene given with options; --slow with a worker twice or a trailing comma;
# --overlay-by without --overlay (a warning); a number that underflows to a denormal; a
# name that is only an ending (-o .png); --stats - and --stats -q; a bad VW_CORES (a
# warning); a scene's resolution too large (file:line).
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
# refused STATUS MESSAGE ARGS...: the run exits STATUS and says MESSAGE (a grep -e
# pattern) on stderr.
refused() {
  want=$1 msg=$2
  shift 2
  "$V" "$@" > out 2> err; rc=$?
  [ $rc -eq "$want" ] || fail "$*: status $rc, expected $want ($(cat err))"
  grep -q -e "$msg" err || fail "$*: message: $(cat err)"
}

# The scenes an unfixed build overwrites are copies: the later cases read s.nff.
"$V" gen spheres --count 20 -o s.nff && "$V" gen cornell -o cb.nff || fail "gen"
for f in victim v1 v2; do cp s.nff $f.nff || exit 1; done
mkdir sub && printf 'frame\n' > script.txt || exit 1
R="--size 8x8 --quiet"

# 1. Two outputs one file, or an output an input: status 2, nothing written.
# shellcheck disable=SC2086
{
refused 2 "^vwalls render: --stats same.png: the same file as -o same.png" \
  render s.nff -o same.png --stats same.png $R
[ ! -e same.png ] || fail "-o same.png --stats same.png: a file was written"
refused 2 "^vwalls render: --stats victim.nff: is the input file victim.nff" \
  render victim.nff -o v.png --stats victim.nff $R
cmp -s s.nff victim.nff || fail "--stats victim.nff: the scene was changed"
[ ! -e v.png ] || fail "--stats victim.nff: the image was written"
refused 2 "the same file as -o same.png" render s.nff -o same.png --overlay same.png $R
refused 2 "the same file as -o ./sub/../o.png" render s.nff -o ./sub/../o.png --overlay o.png $R
ln v1.nff hard.nff && : > tgt.png && ln -s tgt.png link.png || exit 1
refused 2 "--stats hard.nff: is the input file v1.nff" render v1.nff -o x.png --stats hard.nff $R
refused 2 "--overlay link.png: the same file as -o tgt.png" \
  render s.nff -o tgt.png --overlay link.png $R
[ ! -s tgt.png ] || fail "-o tgt.png --overlay link.png: the image was written"
refused 2 "^vwalls animate: --log script.txt: is the input file script.txt" \
  animate s.nff script.txt -o 'fr%02d.png' --log script.txt --quiet
printf 'frame\n' | cmp -s - script.txt || fail "--log script.txt: the script was changed"
refused 2 "^vwalls animate: --stats v2.nff: is the input file v2.nff" \
  animate v2.nff script.txt -o 'fr%02d.png' --stats v2.nff --quiet
refused 2 "^vwalls radiosity: --stats same.ply: the same file as -o same.ply" \
  radiosity cb.nff -o same.ply --stats same.ply --max-shots 2 --quiet
[ ! -e same.ply ] || fail "radiosity -o same.ply --stats same.ply: a file was written"
cp cb.nff cb2.nff || exit 1
refused 2 "^vwalls radiosity: --csv cb2.nff: is the input file cb2.nff" \
  radiosity cb2.nff --csv cb2.nff --max-shots 2 --quiet
cmp -s cb.nff cb2.nff || fail "radiosity --csv cb2.nff: the scene was changed"
# Devices are exempt: both outputs into /dev/null is fine.
"$V" render s.nff -o x.png --overlay ov.png --stats /dev/null $R > /dev/null &&
  "$V" example-pairs --spheres 100 --stats /dev/null --quiet > /dev/null ||
  fail "/dev/null outputs: status $?"
}

# 2, 3. A missing directory is found before the work, as render finds it.
refused 1 "^vwalls gen: -o nodir/x.nff: cannot write: nodir: No such file or directory" \
  gen spheres --count 10 -o nodir/x.nff
refused 1 "^vwalls animate: --log nodir/l.txt: cannot write: nodir" \
  animate s.nff script.txt -o 'fr%02d.png' --log nodir/l.txt --quiet
[ ! -e fr01.png ] && [ ! -e fr00.png ] || fail "--log nodir/l.txt: a frame was drawn"
for c in example-pairs example-components; do
  refused 1 "^vwalls $c: --stats nodir/x.json: cannot write: nodir" $c --stats nodir/x.json
  [ ! -s out ] || fail "$c --stats nodir/x.json: printed a result: $(cat out)"
done

# 4. An option the scene has no use for, given at its default value too.
refused 2 "^vwalls gen: --cluster: 'balls' takes no such option" gen balls --cluster 0
# ... and an unknown scene is named as such, whatever options come with it.
refused 2 "^vwalls gen: unknown generator 'random'" gen random --count 5

# 5. --slow: a worker twice, a trailing comma; --overlay-by alone is a warning.
# shellcheck disable=SC2086
{
refused 2 "^vwalls render: --slow: bad value '1:3,1:4' (worker 1 given twice)" \
  render s.nff -o x.png --workers 2 --slow 1:3,1:4 $R
refused 2 "^vwalls render: --slow: bad value '1:3,'" render s.nff -o x.png --workers 2 --slow 1:3, $R
"$V" render s.nff -o x.png --workers 2 --slow 1:3 $R || fail "--slow 1:3: status $?"
"$V" render s.nff -o x.png --overlay-by worker $R 2> err || fail "--overlay-by alone: status $?"
grep -q "warning: --overlay-by has no effect without --overlay" err ||
  fail "--overlay-by alone: no warning: $(cat err)"
}

# 6. A number that underflows is a number (a denormal, or 0); one that overflows is not.
# shellcheck disable=SC2086
{
"$V" render s.nff -o x.png --from 1e-320,0,0 $R || fail "--from 1e-320,0,0: status $?"
refused 2 "^vwalls render: --from: bad value '1e400,0,0'" render s.nff -o x.png --from 1e400,0,0 $R

# 7. A name that is nothing but its ending.
mkdir od || exit 1
refused 2 "^vwalls render: -o .png: no file name before the ending '.png'" render s.nff -o .png $R
refused 2 "^vwalls render: -o od/.png: no file name" render s.nff -o od/.png $R
[ -z "$(ls -A od)" ] || fail "-o od/.png: wrote $(ls -A od)"
refused 2 "^vwalls gen: -o .nff: no file name" gen cornell -o .nff

# 9. "-" is not standard output; "-q" is an option, not a file name.
refused 2 "^vwalls render: --stats -: standard output is not an output here" \
  render s.nff -o x.png --stats - $R
refused 2 "^vwalls render: --stats needs a value, not the option '-q'" render s.nff -o x.png --stats -q
[ ! -e ./- ] && [ ! -e ./-q ] || fail "--stats - or -q: wrote a file"

# 8. A bad VW_CORES is named once, with the count used instead.
for c in 0 abc -1 5000; do
  VW_CORES=$c "$V" render s.nff -o x.png $R 2> err || fail "VW_CORES=$c: status $?"
  [ "$(grep -c "warning: VW_CORES='$c' is not a whole number from 1 to 1024: ignored, counting the [0-9]* core" err)" -eq 1 ] ||
    fail "VW_CORES=$c: warning: $(cat err)"
done
VW_CORES=2 "$V" render s.nff -o x.png $R 2> err && [ ! -s err ] || fail "VW_CORES=2: $(cat err)"
}

# 10. The scene's resolution, too large: the file's line, and --size.
sed 's/^resolution .*/resolution 100000 100000/' s.nff > big.nff || exit 1
line=$(grep -n '^resolution' big.nff | cut -d: -f1)
refused 2 "^big.nff:$line: resolution 100000x100000 too large .*--size" render big.nff -o b.png --quiet
refused 2 "^big.nff:$line: resolution 100000x100000 too large" \
  animate big.nff script.txt -o 'b%d.png' --quiet
"$V" render big.nff -o b.png --size 8x8 --quiet || fail "--size over a large resolution: status $?"
echo "cli_args: all passed"
