#!/bin/sh
# cli_nff_input.sh VWALLS TMPDIR - binary data named as an NFF is refused as binary data,
# not as its first odd token, and a NUL in a comment of an otherwise good scene (read
# silently before) too: status 2, `file:line: ... binary data, not NFF text` and no
# output, for render, radiosity and info; a UTF-8 comment still renders.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
R="--size 8x8 --quiet"
VIEW='v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45 hither 0.1 resolution 8 8\n'

# A gzip header, and a NUL in a comment on line 3.
printf '\037\213\010\000\000\000\000\000\000\003\n' > garbage.nff
printf "${VIEW}f 1 0 0 1 0 0 0 1\n# \000\ns 0 0 0 1\n" > nul.nff
for f in garbage.nff:1:0x1f nul.nff:3:NUL; do
  n=${f%%:*} line=${f#*:} line=${line%%:*} what=${f##*:}
  case $what in NUL) msg="a NUL byte" ;; *) msg="control character $what" ;; esac
  # shellcheck disable=SC2086
  "$V" render $n -o x.png $R > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "render $n: status $rc ($(cat err))"
  grep -q "$n:$line: $msg: binary data, not NFF text" err || fail "render $n: message: $(cat err)"
  [ ! -e x.png ] || fail "render $n: x.png written"
  "$V" radiosity $n -o x.ply --max-shots 2 --quiet > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "radiosity $n: status $rc ($(cat err))"
  grep -q "$n:$line: $msg: binary data, not NFF text" err || fail "radiosity $n: message: $(cat err)"
  [ ! -e x.ply ] || fail "radiosity $n: x.ply written"
  "$V" info $n > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "info $n: status $rc ($(cat err))"
  grep -q "$n:$line: $msg: binary data, not NFF text" err || fail "info $n: message: $(cat err)"
done
[ -z "$(ls -A | grep -v -x -e garbage.nff -e nul.nff -e out -e err)" ] || fail "left behind: $(ls -A)"

# Comments may hold UTF-8.
printf "${VIEW}f 1 0 0 1 0 0 0 1\n# caf\303\251, 20\302\260\ns 0 0 0 1\n" > utf8.nff
# shellcheck disable=SC2086
"$V" render utf8.nff -o u.png $R > out 2> err || fail "render utf8.nff: status $? ($(cat err))"
[ -s u.png ] || fail "render utf8.nff: no image"
echo "ok"
