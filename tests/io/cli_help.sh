#!/bin/sh
# cli_help.sh VWALLS TMPDIR - the help of the vwalls command: the general usage names
# --version and help COMMAND; `vwalls help CMD` prints what `vwalls CMD --help` prints
# (it used to print the general usage); every command's help has a --help line and an
# exit status line; the help names the options' enforced limits, -q and --output.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

"$V" --help > usage.txt || fail "--help: status $?"
grep -q -- '--version' usage.txt || fail "--help does not mention --version"
grep -q 'vwalls help COMMAND' usage.txt || fail "--help does not mention vwalls help COMMAND"
"$V" help > help.txt || fail "help: status $?"
cmp -s usage.txt help.txt || fail "vwalls help differs from vwalls --help"
cmds=$(sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p' usage.txt)
[ -n "$cmds" ] || fail "no commands in the usage"
for c in $cmds; do
  "$V" help "$c" > a.txt 2>&1 || fail "help $c: status $?"
  "$V" "$c" --help > b.txt 2>&1 || fail "$c --help: status $?"
  cmp -s a.txt b.txt || fail "vwalls help $c differs from vwalls $c --help"
  grep -q -- '^ *--help ' b.txt || fail "$c --help: no --help line"
  grep -qi '^exit status: ' b.txt || fail "$c --help: no exit status line"
done
# Accepted options and enforced limits are in the help: -q and --output, the ranges
# the option parsers refuse beyond.
for c in render animate edit; do
  "$V" $c --help > h.txt || fail "$c --help: status $?"
  grep -q -- '-q, --quiet' h.txt && grep -q -- '-o, --output' h.txt ||
    fail "$c --help: -q or --output missing"
done
"$V" render --help > h.txt
for limit in 'depth, 1 to 64' 'per process, 1 to 1024' '32768 cells' 'N from 1 to 256' \
             'rounds, 1 to 20'; do
  grep -q -- "$limit" h.txt || fail "render --help: no '$limit'"
done
"$V" gen --help > h.txt
for limit in 'at most 7 for balls, 120 for rings, 13 for tree' 'at most 20000000'; do
  grep -q -- "$limit" h.txt || fail "gen --help: no '$limit'"
done
"$V" help bogus 2> err; rc=$?
[ $rc -eq 2 ] && grep -q "unknown command 'bogus'" err || fail "help bogus: status $rc, $(cat err)"
echo "cli_help: all passed"
