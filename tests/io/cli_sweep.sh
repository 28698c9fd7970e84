#!/bin/sh
# cli_sweep.sh VWALLS TMPDIR - what a robustness sweep of the command line found: an output
# naming a material library the scene read (render --stats x.mtl replaced x.obj's
# library), the checkpoint radiosity resumes from (--stats CK replaced it; --checkpoint CK
# stays allowed), or one of animate's or edit's frames (--log f01.png with -o f%02d.png
# replaced frame 1); an empty --slow, and numbers with white space or a '+' before them
# (" 2", "+8x8"), which strtol took. Each is refused with status 2 before anything is
# written. Then every numeric option of every command with values that are not numbers
# or out of range: status 2 and a message naming the option and the value, hexadecimal
# numbers among them ("--angle 0x10", which strtod read as 16 degrees). Then what the
# next sweep found: radiosity took options it had no use for without a word (--size or
# --view without --image, --checkpoint-every without --checkpoint, --max-level without
# --subdivide, --snapshot-every without an output it rewrites), now a warning each, as
# render warns; edit took animate's --keep-going, now an unknown option (status 2); and
# hexadecimal numbers in the lists of reals (--from, --light, --view, --speeds, --slow).
set -u
V=$1 T=$2
D=$(cd "$(dirname "$0")/../data" && pwd) || exit 1
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
# refused STATUS MESSAGE ARGS...: the run exits STATUS and says MESSAGE (a grep -e
# pattern) on stderr.
refused() {
  want=$1 msg=$2
  shift 2
  "$V" "$@" > out 2> err < /dev/null; rc=$?
  [ $rc -eq "$want" ] || fail "$*: status $rc, expected $want ($(cat err))"
  grep -q -e "$msg" err || fail "$*: message: $(cat err)"
}
# clean: no output and no temporary file in the directory besides the fixtures.
clean() {
  left=$(ls -A | grep -v -x -e cube.obj -e cube.mtl -e mtl.orig -e s.nff -e script.txt \
         -e ck -e ck.orig -e out -e err)
  [ -z "$left" ] || fail "$*: left behind: $left"
}

cp "$D/good/cube.obj" "$D/good/cube.mtl" . && cp cube.mtl mtl.orig || exit 1
"$V" gen spheres --count 20 -o s.nff || fail "gen"
printf 'frame\nframe\n' > script.txt || exit 1
R="--size 8x8 --quiet"

# 1. A material library is an input: refused, the library intact, nothing written.
# shellcheck disable=SC2086
{
refused 2 "^vwalls render: --stats cube.mtl: is the input file ./cube.mtl: it would be overwritten" \
  render cube.obj -o o.png --stats cube.mtl $R
cmp -s cube.mtl mtl.orig || fail "render --stats cube.mtl: the library was changed"
clean "render --stats cube.mtl"
refused 2 "^vwalls radiosity: --csv ./cube.mtl: is the input file ./cube.mtl" \
  radiosity cube.obj -o o.ply --csv ./cube.mtl --max-shots 3 --quiet
cmp -s cube.mtl mtl.orig || fail "radiosity --csv cube.mtl: the library was changed"
clean "radiosity --csv cube.mtl"
refused 2 "^vwalls animate: --log cube.mtl: is the input file ./cube.mtl" \
  animate cube.obj script.txt -o 'f%02d.png' --log cube.mtl $R
cmp -s cube.mtl mtl.orig || fail "animate --log cube.mtl: the library was changed"
clean "animate --log cube.mtl"
# The same scene with other outputs still works.
"$V" render cube.obj -o o.png --stats o.json $R || fail "render cube.obj: status $?"
rm -f o.png o.json
}

# 2. The checkpoint resumed from is an input of every output but --checkpoint.
"$V" radiosity cube.obj --checkpoint ck --max-shots 3 --quiet && cp ck ck.orig ||
  fail "radiosity --checkpoint ck: status $?"
for o in --stats --trace --csv; do
  refused 2 "^vwalls radiosity: $o ./ck: is the input file ck: it would be overwritten" \
    radiosity cube.obj --resume ck $o ./ck --max-shots 6 --quiet
  cmp -s ck ck.orig || fail "radiosity --resume ck $o ./ck: the checkpoint was changed"
  clean "radiosity --resume ck $o ./ck"
done
"$V" radiosity cube.obj --resume ck --checkpoint ck --max-shots 6 --quiet ||
  fail "radiosity --resume ck --checkpoint ck: status $?"
rm -f ck ck.orig

# 3. A frame file is the frames' own: --log or --stats naming one is refused.
# shellcheck disable=SC2086
{
refused 2 "^vwalls animate: --log f01.png: frame 1 of -o f%02d.png: one would overwrite the other" \
  animate s.nff script.txt -o 'f%02d.png' --log f01.png $R
clean "animate --log f01.png"
refused 2 "^vwalls animate: --stats ./f0.png: frame 0 of -o f%d.png" \
  animate s.nff script.txt -o 'f%d.png' --stats ./f0.png $R
clean "animate --stats ./f0.png"
refused 2 "^vwalls animate: --stats f15.png: frame 5 of -o f1%d.png" \
  animate s.nff script.txt -o 'f1%d.png' --stats f15.png $R
refused 2 "^vwalls edit: --log f00.png: frame 0 of -o f%02d.png" \
  edit s.nff -o 'f%02d.png' --log f00.png $R
clean "edit --log f00.png"
# A name that only looks like one is not: f0.png is no frame of f%02d.png.
"$V" animate s.nff script.txt -o 'f%02d.png' --stats f0.png $R > /dev/null ||
  fail "animate -o f%02d.png --stats f0.png: status $?"
[ -s f00.png ] && [ -s f01.png ] && [ -s f0.png ] || fail "f%02d.png --stats f0.png: $(ls)"
rm -f f00.png f01.png f0.png
}

# 4. An empty --slow, and white space or '+' before a number, whole or real.
# shellcheck disable=SC2086
{
refused 2 "^vwalls render: --slow: bad value ''" render s.nff -o o.png --workers 2 --slow '' $R
refused 2 "^vwalls render: --slow: bad value ' 0:2'" render s.nff -o o.png --workers 2 --slow ' 0:2' $R
refused 2 "^vwalls render: --workers: bad value ' 2'" render s.nff -o o.png --workers ' 2' $R
refused 2 "^vwalls render: --depth: bad value '+3'" render s.nff -o o.png --depth +3 $R
refused 2 "^vwalls render: --size: bad value '+8x8'" render s.nff -o o.png --size +8x8 --quiet
refused 2 "^vwalls render: --size: bad value '8x 8'" render s.nff -o o.png --size '8x 8' --quiet
refused 2 "^vwalls gen: --count: bad value ' 5'" gen spheres --count ' 5'
# Real numbers too, as whole numbers (strtod takes both).
refused 2 "^vwalls render: --angle: bad value ' 45'" render s.nff -o o.png --angle ' 45' --quiet
refused 2 "^vwalls render: --angle: bad value '+45'" render s.nff -o o.png --angle +45 --quiet
refused 2 "^vwalls render: --from: bad value '0, 0,5'" render s.nff -o o.png --from '0, 0,5' \
  --quiet
refused 2 "^vwalls render: --from: bad value '+1,0,5'" render s.nff -o o.png --from +1,0,5 \
  --quiet
refused 2 "^vwalls render: --slow: bad value '1:+2'" render s.nff -o o.png --workers 2 \
  --slow 1:+2 $R
refused 2 "^vwalls render: --speeds: bad value '1, 2'" render s.nff -o o.png --workers 2 \
  --speeds '1, 2' $R
refused 2 "^vwalls render: --speeds: bad value '+1,2'" render s.nff -o o.png --workers 2 \
  --speeds +1,2 $R
refused 2 "^vwalls gen: --cluster: bad value ' 0.5'" gen spheres --cluster ' 0.5'
clean "white space"
"$V" render s.nff -o o.png --workers 2 --slow 1:2 --depth 3 --size 8X8 --quiet ||
  fail "--slow 1:2 --depth 3 --size 8X8: status $?"
rm -f o.png
}

# 5. Every numeric option, with values that are no numbers or out of range.
# bad CMD OPTION VALUE ARGS...: status 2, "vwalls CMD: OPTION: bad value 'VALUE'".
bad() {
  c=$1 o=$2 v=$3
  shift 3
  refused 2 "^vwalls $c: $o: bad value '$v'" "$c" "$@" "$o" "$v"
}
for v in 0 -1 nan 1e999 '' 9223372036854775808 1.5 0x10 inf; do
  for o in --workers --depth --balance-iters --prepass; do
    bad render $o "$v" s.nff -o o.png --quiet
  done
  for o in --workers --depth; do
    bad animate $o "$v" s.nff script.txt -o 'f%d.png' --quiet
  done
  for o in --workers --hemicube --elements --per-round --max-shots --stall-shots \
           --max-rounds --snapshot-every; do
    bad radiosity $o "$v" cube.obj -o o.ply --quiet
  done
  for o in --spheres --workers; do
    [ "$o$v" = --spheres0 ] && continue # no spheres, no pairs: a fine question
    bad example-pairs $o "$v" --quiet
    bad example-components $o "$v" --quiet
  done
  bad gen --count "$v" spheres
done
# 0x1p-4 is 0.0625 and -0x0 is 0: in range for each of them, had they been decimal.
for v in nan 1e999 '' -1 inf 1e400 abc 1,2 0x1p-4 0X.1 -0x0 ' 0x1p-4'; do
  for o in --sf --patch-size --neighbourhood --subdivide --checkpoint-every; do
    bad radiosity $o "$v" cube.obj -o o.ply --quiet
  done
  bad render --angle "$v" s.nff -o o.png --quiet
  bad animate --threshold "$v" s.nff script.txt -o 'f%d.png' --quiet
  bad animate --margin "$v" s.nff script.txt -o 'f%d.png' --quiet
  bad example-pairs --radius "$v" --quiet
  bad gen --cluster "$v" spheres
done
for v in 0x2 2x 2x2x2x2 -1 '' 33x33x33 x; do
  refused 2 "^vwalls render: --cells: layout '$v'" render s.nff -o o.png --cells "$v" --quiet
  refused 2 "^vwalls radiosity: --cells: layout '$v'" radiosity cube.obj -o o.ply --cells "$v"
done
clean "numeric options"

# 6. radiosity: an option whose only user is absent is a warning (render's words for
# --overlay-by), the run goes on; with its user, no warning.
# warned OPTION WITHOUT ARGS...: status 0, "vwalls radiosity: warning: OPTION has no
# effect without WITHOUT" on stderr, and the mesh written.
warned() {
  o=$1 without=$2
  shift 2
  "$V" radiosity cube.obj -o o.ply --max-shots 3 --quiet "$@" > out 2> err < /dev/null ||
    fail "radiosity $*: status $? ($(cat err))"
  grep -q -x -e "vwalls radiosity: warning: $o has no effect without $without" err ||
    fail "radiosity $*: no warning about $o: $(cat err)"
  [ -s o.ply ] || fail "radiosity $*: no mesh"
  rm -f o.ply ck
}
warned --size --image --size 8x8
warned --view --image --view 0,0,5,0,0,0
warned --checkpoint-every --checkpoint --checkpoint-every 5
warned --max-level --subdivide --max-level 2
"$V" radiosity cube.obj --stats o.json --snapshot-every 2 --max-shots 3 --quiet > out 2> err ||
  fail "radiosity --stats --snapshot-every: status $?"
grep -q -x -e "vwalls radiosity: warning: --snapshot-every has no effect without -o, --csv or --image (the outputs it rewrites)" err ||
  fail "radiosity --stats --snapshot-every: no warning: $(cat err)"
[ -s o.json ] || fail "radiosity --stats --snapshot-every: no stats"
rm -f o.json
warned --size --image --size 8x8 --view 0,0,5,0,0,0 --checkpoint ck --subdivide 0.1
grep -q -e "--view has no effect" err || fail "--size and --view: one warning each: $(cat err)"
grep -q -e "--checkpoint\|--max-level" err && fail "unasked-for warning: $(cat err)"
"$V" radiosity cube.obj -o o.ply --image o.png --size 8x8 --view 0,0,5,0,0,0 --checkpoint ck \
  --checkpoint-every 5 --subdivide 0.1 --max-level 2 --snapshot-every 2 --max-shots 3 \
  --quiet > out 2> err < /dev/null || fail "radiosity, every option used: status $?"
grep -q "warning" err && fail "radiosity, every option used: $(cat err)"
[ -s o.ply ] && [ -s o.png ] && [ -s ck ] || fail "radiosity, every option used: $(ls)"
rm -f o.ply o.png ck

# 7. --keep-going is animate's: edit refuses it as any option it does not take, before
# reading a line; its help does not list it, animate's does.
echo frame > in.txt
"$V" edit s.nff --keep-going --quiet > out 2> err < in.txt; rc=$?
[ $rc -eq 2 ] || fail "edit --keep-going: status $rc, expected 2 ($(cat err))"
grep -q "^vwalls edit: unknown option '--keep-going'" err || fail "edit --keep-going: $(cat err)"
[ -s out ] && fail "edit --keep-going: answered: $(cat out)"
rm -f in.txt
"$V" edit --help | grep -q -e "^  --keep-going  " && fail "edit --help lists --keep-going"
"$V" animate --help | grep -q -e "^  --keep-going  " || fail "animate --help: no --keep-going"

# 8. Hexadecimal numbers in the lists of real numbers; decimal and exponent forms stay.
# shellcheck disable=SC2086
{
refused 2 "^vwalls render: --from: bad value '0,0x1p-4,5'" render s.nff -o o.png --from 0,0x1p-4,5 $R
refused 2 "^vwalls render: --light: bad value '1,1,1,0X.8,1,1'" render s.nff -o o.png \
  --light 1,1,1,0X.8,1,1 $R
refused 2 "^vwalls radiosity: --view: bad value '0,0,5,0,0,0,0x10'" radiosity cube.obj -o o.ply \
  --image o.png --view 0,0,5,0,0,0,0x10 --quiet
refused 2 "^vwalls render: --speeds: bad value '1,0x2'" render s.nff -o o.png --workers 2 \
  --speeds 1,0x2 $R
refused 2 "^vwalls render: --speeds: bad value ' 0x1,1'" render s.nff -o o.png --workers 2 \
  --speeds ' 0x1,1' $R
refused 2 "^vwalls render: --slow: bad value '1:0x2'" render s.nff -o o.png --workers 2 \
  --slow 1:0x2 $R
clean "hexadecimal lists"
"$V" render s.nff -o o.png --angle 2.5E1 --from 1e-3,0,5 --at 0,0,0 --up 0,1E0,0 \
  --light 1,1,1,5e-1,.5,0.5 --workers 2 --speeds 1,2.5E0 --slow 1:2e0 $R ||
  fail "render, decimal and exponent forms: status $?"
"$V" radiosity cube.obj -o o.ply --sf 1E-3 --patch-size 2.5e0 --subdivide 1e-1 \
  --checkpoint ck --checkpoint-every 1e2 --max-shots 3 --quiet ||
  fail "radiosity, decimal and exponent forms: status $?"
"$V" animate s.nff script.txt -o 'f%d.png' --threshold 1e-1 --margin 2.5E-1 $R > /dev/null ||
  fail "animate, decimal and exponent forms: status $?"
"$V" gen spheres --count 3 --cluster 5E-1 -o g.nff || fail "gen --cluster 5E-1: status $?"
rm -f o.png o.ply ck f0.png f1.png g.nff
}
clean "unused options"
echo "cli_sweep: all passed"
