#!/bin/sh
# cli_shown.sh VWALLS TMPDIR - `vwalls animate scene.nff garbage.bin` printed the script's
# raw bytes (escape sequences, control characters) in its messages: now every byte on
# stderr is printable ASCII or a line end, the bad words shown with '?', status 2 and no
# frame.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$V" gen spheres --count 5 -o s.nff > /dev/null || fail "gen: status $?"
printf 'frame\n\033[2J\001boom\nmove 1 \033[31m 0 0\nadd sphere 0 0 0 1 \233x\n' > garbage.bin
"$V" animate s.nff garbage.bin -o 'f%02d.png' --size 8x8 > out 2> err; rc=$?
[ $rc -eq 2 ] || fail "animate: status $rc ($(cat err))"
[ -z "$(ls f*.png 2>/dev/null)" ] || fail "animate: a frame was written"
LC_ALL=C grep -q '[^ -~]' err && fail "animate: unprintable bytes on stderr: $(od -c err | head)"
grep -q "^garbage.bin:2: unknown command '?\[2J?boom'" err &&
  grep -q "^garbage.bin:3: bad number '?\[31m'" err &&
  grep -q "^garbage.bin:4: bad material index '?x'" err || fail "animate: messages: $(cat err)"
echo "ok"
