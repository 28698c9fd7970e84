#!/bin/sh
# cli_obj_input.sh VWALLS TMPDIR - binary data named as an OBJ (`vwalls render garbage.obj`
# exited 0 with a black image): status 2, `file:line: ...` and no output, for render and
# radiosity; an OBJ with an unknown keyword renders, with one warning on stderr.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
R="--size 8x8 --quiet"

# An ELF header's first bytes, and a NUL in a comment of an otherwise good mesh.
printf '\177ELF\002\001\001\000\000\000\000\000\n' > garbage.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n# \000\nf 1 2 3\n' > nul.obj
for f in garbage.obj nul.obj; do
  # shellcheck disable=SC2086
  "$V" render $f -o x.png $R > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "render $f: status $rc ($(cat err))"
  grep -q "^$f:[0-9]*: .*binary data, not OBJ text" err || fail "render $f: message: $(cat err)"
  [ ! -e x.png ] || fail "render $f: x.png written"
  "$V" radiosity $f -o x.ply --max-shots 2 --quiet > out 2> err; rc=$?
  [ $rc -eq 2 ] || fail "radiosity $f: status $rc ($(cat err))"
  [ ! -e x.ply ] || fail "radiosity $f: x.ply written"
done
[ -z "$(ls -A | grep -v -x -e garbage.obj -e nul.obj -e out -e err)" ] || fail "left behind: $(ls -A)"

# A vendor's keyword: rendered, one warning for two unknown keywords.
printf 'v 0 0 0\nv 1 0 0\nacme_lod 3\nv 0 1 0\nacme_tag x\nf 1 2 3\n' > vendor.obj
# shellcheck disable=SC2086
"$V" render vendor.obj -o v.png $R > out 2> err || fail "render vendor.obj: status $? ($(cat err))"
[ -s v.png ] || fail "render vendor.obj: no image"
[ "$(grep -c warning err)" -eq 1 ] && grep -q "^vendor.obj:3: warning: unknown keyword 'acme_lod'" err ||
  fail "render vendor.obj: warnings: $(cat err)"
echo "ok"
