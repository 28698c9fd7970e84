#!/bin/sh
# cli_outputs.sh VWALLS TMPDIR - the output files of the vwalls command: -o naming a
# symbolic link keeps the link and writes the file it leads to; a FIFO or a device node
# stays what it was (written in place; a full device is status 1, "No space left on
# device"); gen and radiosity write mode 0644 under umask 022 (radiosity's used to be
# 0600); SIGTERM while gen writes a big file leaves no "*.tmp.*" and the status says
# killed by SIGTERM; an empty output name is a usage error (status 2) for every command.
# Device nodes are made here with mknod (skipped when not permitted); /dev is not touched.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
no_temps() { ! ls -a "$@" | grep '\.tmp\.' || fail "temporary files left behind in $*"; }

# A symbolic link (relative, from another directory) stays a link; its target gets the
# scene. A dangling one is refused and nothing is created where it points.
"$V" gen cornell -o real.nff || fail "gen cornell"
mkdir sub && ln -s ../real.nff sub/link.nff || exit 1
"$V" gen spheres --count 10 -o sub/link.nff || fail "-o a link: status $?"
[ -L sub/link.nff ] || fail "-o a link: the link was replaced by a file"
[ "$(readlink sub/link.nff)" = ../real.nff ] || fail "-o a link: it points elsewhere now"
"$V" gen spheres --count 10 -o ref.nff || fail "gen spheres"
cmp -s real.nff ref.nff || fail "-o a link: its target does not hold the scene"
ln -s missing.nff dangling.nff || exit 1
"$V" gen cornell -o dangling.nff 2> err; rc=$?
[ $rc -eq 1 ] || fail "-o a dangling link: status $rc, expected 1"
grep -q 'dangling.nff: is a symbolic link to a file that does not exist' err ||
  fail "-o a dangling link: message: $(cat err)"
[ -L dangling.nff ] && [ ! -e missing.nff ] || fail "-o a dangling link: a file was created"
no_temps . sub

# A FIFO: the reader gets the scene, the FIFO stays a FIFO. (Checked before waiting for
# the reader: had the FIFO been replaced, the reader would wait for ever.)
mkfifo fifo || exit 1
cat fifo > from_fifo & reader=$!
"$V" gen cornell -o fifo; rc=$?
if [ ! -p fifo ]; then kill $reader; fail "-o a FIFO: it was replaced by a file"; fi
[ $rc -eq 0 ] || { echo > fifo; fail "-o a FIFO: status $rc"; }
wait $reader
"$V" gen cornell > cornell.nff || fail "gen to stdout"
cmp -s from_fifo cornell.nff || fail "-o a FIFO: the reader did not get the scene"

# Device nodes: copies of /dev/null and /dev/full made here.
if mknod null c 1 3 2> mknod.err && mknod full c 1 7; then
  "$V" gen cornell -o null || fail "-o a null device: status $?"
  [ -c null ] || fail "-o a null device: it was replaced by a file"
  "$V" gen cornell -o full 2> err; rc=$?
  [ $rc -eq 1 ] || fail "-o a full device: status $rc, expected 1"
  grep -q 'full: write failed: No space left on device' err || fail "-o a full device: message: $(cat err)"
  [ -c full ] || fail "-o a full device: it was replaced by a file"
else
  echo "device nodes skipped: mknod not permitted"
fi
no_temps .

# Modes follow the umask, radiosity's outputs as every other.
(umask 022 && "$V" gen cornell -o m.nff &&
  "$V" radiosity m.nff -o m.ply --csv m.csv --trace m.trace --checkpoint m.ck --max-shots 4 --quiet) ||
  fail "umask 022 runs"
for f in m.nff m.ply m.csv m.trace m.ck; do
  m=$(stat -c %a "$f")
  [ "$m" = 644 ] || fail "$f: mode $m under umask 022, expected 644"
done

# SIGTERM as soon as gen's temporary file appears: gone with the process, which ends
# by the signal (status 128+15).
"$V" gen spheres --count 1000000 -o big.nff & pid=$!
i=0
while [ $i -lt 1000 ] && ! ls | grep -q '^big\.nff\.tmp\.'; do sleep 0.01; i=$((i + 1)); done
ls | grep -q '^big\.nff\.tmp\.' || { kill $pid; fail "SIGTERM: no temporary file appeared"; }
kill -TERM $pid
wait $pid; rc=$?
[ $rc -eq 143 ] || fail "SIGTERM: status $rc, expected 143 (killed by SIGTERM)"
[ ! -e big.nff ] || fail "SIGTERM: big.nff was written"
no_temps .

# An empty output name: status 2 and "OPTION: empty file name", for every command.
printf 'frame\n' > edits.txt
for args in "gen cornell -o" "render m.nff -o" "render m.nff --output" "render m.nff -o x.png --stats" \
            "render m.nff -o x.png --overlay" "radiosity m.nff -o" "radiosity m.nff --csv" \
            "radiosity m.nff --image" "radiosity m.nff --stats" "radiosity m.nff -o x.ply --trace" \
            "radiosity m.nff --checkpoint" "animate m.nff edits.txt -o f%d.png --log" \
            "animate m.nff edits.txt -o f%d.png --stats" "edit m.nff --log" \
            "example-pairs --stats" "example-components --stats"; do
  # shellcheck disable=SC2086
  "$V" $args "" > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "$args '': status $rc, expected 2"
  grep -q -- "^vwalls [a-z-]*: ${args##* }: empty file name\$" err || fail "$args '': message: $(cat err)"
done
# A forgotten value: the next option is not taken as the file name (it used to write a
# file named --quiet).
"$V" example-pairs --stats --quiet > out 2> err; rc=$?
[ $rc -eq 2 ] || fail "--stats --quiet: status $rc, expected 2"
grep -q -- "--stats needs a value, not the option '--quiet'" err || fail "--stats --quiet: message: $(cat err)"
[ ! -e ./--quiet ] || fail "--stats --quiet: a file named --quiet was written"
echo "cli_outputs: all passed"
