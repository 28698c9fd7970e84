#!/bin/sh
# tutorial_snippets.sh - the C code shown in docs/tutorial.md is the code that is built
# and tested: every line of every ```c block must be a line of docs/tutorial/*.[ch].
#   usage: tutorial_snippets.sh TUTORIAL.md SOURCE...
set -eu
md=$1; shift
tmp=$(mktemp); trap 'rm -f "$tmp"' EXIT
cat "$@" >"$tmp"     # one file, so that FNR == NR holds for the sources alone
awk '
  FNR == NR { src[$0] = 1; next }
  /^```c$/ { inblock = 1; next }
  /^```/   { inblock = 0; next }
  inblock && $0 !~ /^[[:space:]]*$/ && !($0 in src) {
    printf "%s:%d: not in the tutorial sources: %s\n", FILENAME, FNR, $0; bad = 1
  }
  END { exit bad }
' "$tmp" "$md"
